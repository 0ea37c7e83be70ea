#include "validate/report/first_screen.hpp"

#include <fmt/format.h>

#include <cmath>

#include "validate/report/report_tables.hpp"

namespace rdyn::validate {

namespace {

using json = nlohmann::json;
using namespace report_format;

// "the speed and the knee force": the quantities the recommended setting was chosen on.
std::string chosen_on_words(const std::string& q) {
  return q == "qdot" ? "the speed" : "the speed and the " + quantity_words(q);
}

// A run's errors on the speed and the headline quantity, "a and b of their peaks".
std::string chosen_errors(const json& run, const std::string& q) {
  if (q == "qdot") return pct(error_of(run, "qdot")) + " of its peak";
  return pct(error_of(run, "qdot")) + " and " + pct(error_of(run, q)) + " of their peaks";
}

// Whether the full run compared with is at least as accurate as the recommended run on the
// quantities it was chosen on — read from their errors, not from a flag a hand-edited (or older)
// summary may lack or contradict: the wording "at equal or better error" must be true.
bool full_as_accurate(const json& s, const json& rec, const json& full) {
  for (const std::string& q : {std::string("qdot"), str(s, "headline_quantity")})
    if (!(error_of(full, q) <= error_of(rec, q))) return false;
  return true;
}

// The one speedup: the recommended run against the cheapest full run at equal or better error
// (validate/harness/verdicts.hpp, pick_matched_full), or the reference when none was as accurate.
std::string speedup_sentence(const json& s) {
  const json& rec = s.at("recommended_reduced");
  const json& full = s.value("recommended_full", json(nullptr));
  const std::string Q = str(s, "headline_quantity");
  if (!s.value("recommended_speedup", json(nullptr)).is_number())
    return "No speedup is claimed (the summary has none: the compared window is too short to judge errors, or "
           "the timing was not measured).";
  const double x = d(s, "recommended_speedup");
  if (full.is_object() && !full_as_accurate(s, rec, full))
    return fmt::format("No run of the full-model ladder was as accurate on {}. Its most accurate, {}, {} (errors {} "
                       "against the recommended setting's {}), is not as accurate on all of them, and the "
                       "recommended setting is <b>{}× faster</b> than it: at least that much faster than Simbody "
                       "at equal error (the reference, far more accurate, is in the baselines below).",
                       H(chosen_on_words(Q)), H(str(full, "label")), H(cost(s, d(full, "wall_s"))),
                       H(chosen_errors(full, Q)), H(chosen_errors(rec, Q)), num(x, "{:.3g}"));
  if (full.is_object())
    return fmt::format("It is <b>{}× faster</b> than Simbody forward dynamics at equal or better error: the "
                       "cheapest full-model run as accurate on {} is {}, {} (errors {} against the recommended "
                       "setting's {}).",
                       num(x, "{:.3g}"), H(chosen_on_words(Q)), H(str(full, "label")), H(cost(s, d(full, "wall_s"))),
                       H(chosen_errors(full, Q)), H(chosen_errors(rec, Q)));
  const json& ref = s.at("reference");
  return fmt::format("No run of the full-model ladder was as accurate on {}: against the reference (Simbody at "
                     "tolerance {}, {}) it is <b>{}× faster</b>.",
                     H(chosen_on_words(Q)), num(d(ref, "tolerance"), "{:.0e}"),
                     H(cost(s, d(ref, "wall_s"))),
                     num(x, "{:.3g}"));
}

// What decided the status: the scene's thresholds, each on the grid it declares (their table is
// below the figures), in one line.
std::string thresholds_line(const json& s) {
  const auto& th = s.value("thresholds", json::array());
  if (th.empty()) return "";
  std::string failed;
  int n_failed = 0;
  for (const auto& t : th)
    if (!t.value("pass", false)) {
      ++n_failed;
      failed += fmt::format("{}{} {} on the {}° grid (limit {})", failed.empty() ? "" : "; ", H(str(t, "quantity")),
                            pct(d(t, "error")), num(d(t, "grid_deg")), pct(d(t, "max_error")));
    }
  const std::string whose = s.value("thresholds_are_defaults", false)
                                ? "the default acceptance thresholds (the scene declares none)"
                                : "the scene's acceptance thresholds";
  if (n_failed == 0)
    return fmt::format("<p>The status is decided by {}, each judged on the grid it declares (table \"Acceptance "
                       "thresholds\" below): all {} pass.</p>",
                       whose, th.size());
  return fmt::format("<p class=warn>The status is decided by {}, each judged on the grid it declares (table "
                     "\"Acceptance thresholds\" below): {} of {} fail: {}.</p>",
                     whose, n_failed, th.size(), failed);
}

// The cost of the accurate rows the errors are read from: an untimed second run of the
// recommended setting (one extra single step of its method per output row).
std::string row_cost(const json& s) {
  const json& rec = s.at("recommended_reduced");
  const double timed = d(rec, "wall_s"), rows = d(rec, "compared_run_wall_s");
  if (!(timed > 0) || !(rows > 0)) return "";
  return fmt::format(
      "The accurate rows come from an untimed second run of that setting (one extra single step "
      "per output row): {} against {} for the timed run, {}× (one run, noisy).",
      secs(rows), secs(timed), num(rows / timed, "{:.2g}"));
}

std::string verdict_rows(const json& s) {
  std::string h = "<table><tr><th>quantity</th><th>max error " + H(compared_over(s)) +
                  " at the recommended setting</th><th>target</th><th></th></tr>";
  for (const auto& v : s.at("verdicts")) {
    const bool within = v.value("within_target", false);
    h += fmt::format("<tr><td class=l>{}</td><td>{}</td><td>{}</td><td class={}>{}</td></tr>", H(str(v, "quantity")),
                     pct(d(v, "error")), pct(d(v, "target")), within ? "pass" : "fail",
                     within ? "within target" : "above target");
  }
  return h + "</table>";
}

std::string baselines_rows(const json& s) {
  if (s.at("baselines").empty()) return "";
  std::string h =
      "<table><tr><th>baseline (full model)</th><th>run</th><th>its cost</th><th>recommended setting is</th></tr>";
  for (const auto& b : s.at("baselines"))
    h += fmt::format("<tr><td class=l>{}</td><td class=l>{}</td><td class=l>{}</td><td>{}× faster</td></tr>",
                     H(str(b, "what")), H(str(b, "label")), H(cost(s, d(b, "wall_s"))), num(d(b, "speedup"), "{:.3g}"));
  return h + "</table>";
}

std::string error_budget(const json& s) {
  if (!s.contains("error_budget")) return "";
  const auto& b = s.at("error_budget");
  return fmt::format(
      "<p><b>Error budget</b> of {} at the recommended setting ({} of its peak, on output rows "
      "computed as accurately as the integrator's steps): reference {} (its change when its "
      "tolerance is halved), table {} ({}: grid and interpolation, integrated at the tightest "
      "tolerance), integration {} (what the setting's integrator adds). Output interpolation {}: "
      "what quintic-Hermite rows between steps, as the timed run writes them, differ from "
      "those rows (not in the total). Contributions are maxima, so they bound rather than "
      "sum. {}</p>",
      H(str(b, "quantity")), pct(d(b, "total")), pct(d(b, "reference")), pct(d(b, "table")),
      H(str(b, "table_run").empty() ? "no tight run at that grid" : str(b, "table_run")), pct(d(b, "integration")),
      pct(d(b, "output_interpolation")), row_cost(s));
}

// A run's errors on every quantity but the speed and mean speed: a phrase each, the joint
// outputs as their largest.
std::string other_errors(const json& s, const json& run) {
  std::string out, worst_joint;
  double worst = -1;
  for (const auto& q : s.at("quantities")) {
    if (q == "qdot" || q == "mean_qdot") continue;
    if (is_joint_output(s, q)) {
      const double e = error_of(run, q);
      if (!(e <= worst)) worst = e, worst_joint = q.get<std::string>();
      continue;
    }
    out += fmt::format(" and {} for {}", pct(error_of(run, q)), q.get<std::string>());
  }
  if (!worst_joint.empty())
    out += fmt::format(", and at most {} for the {} joint outputs ({})", pct(worst),
                       s.value("joint_output_quantities", json::array()).size(), worst_joint);
  return out;
}

// The reference's accuracy: its change when its tolerance is halved, per quantity.
std::string reference_sentence(const json& s) {
  const auto& ref = s.at("reference");
  std::string out = fmt::format(
      "Reference: the full model (Simbody, {}) at tolerance {}; halving that tolerance changed",
      str(ref, "integrator") == "rkmerson" ? "Runge–Kutta–Merson" : str(ref, "integrator"),
      num(d(ref, "tolerance"), "{:.0e}"));
  const auto& ch = ref.at("change_when_tolerance_halved").at("errors");
  bool first = true;
  double joint_change = -1;
  for (const auto& q : s.at("quantities")) {
    const std::string name = q.get<std::string>();
    if (name == "mean_qdot" || !ch.contains(name)) continue;
    if (is_joint_output(s, q)) {
      joint_change = std::max(joint_change, d(ch[name], "max_rel"));
      continue;
    }
    out += fmt::format("{} {} by {}", first ? "" : " and", name == "qdot" ? "the speed" : name,
                       pct(d(ch[name], "max_rel")));
    first = false;
  }
  if (joint_change >= 0) out += fmt::format(" and the joint outputs by at most {}", pct(joint_change));
  out += " of their peaks. ";
  const auto& w = s.at("steady_window");
  // A range-limited coordinate oscillates or moves within its range: cycles are not its words.
  const bool in_range = w.value("how", std::string()).find("within a range") != std::string::npos;
  out += !w.value("whole_run", false) ? "Errors are maxima " + compared_over(s) + "."
         : in_range                   ? "The coordinate moves within a range: errors are maxima over the whole run."
                                      : "The run has no steady cycles: errors are maxima over the whole run.";
  return out;
}

// The recommended setting's table: what extracting it costs beside one run of the full model.
std::string extraction_sentence(const json& s, const json& rec, const json& full) {
  for (const auto& e : s.at("extractions"))
    if (std::abs(d(e, "grid_deg") - d(rec, "grid_deg")) < 1e-9) {
      std::string out = fmt::format("Its {}° table costs {} ms to extract once", num(d(e, "grid_deg")),
                                    num(d(e, "ms"), "{:.3g}"));
      if (s.value("per_second_measured", false) && full.is_object())
        out += fmt::format(" (as long as {} s of simulated motion with that full run)",
                           num(d(e, "ms") * 1e-3 / d(full, "wall_s_per_simulated_s"), "{:.3g}"));
      return out + ". ";
    }
  return "";
}

}  // namespace

std::string first_screen_html(const json& s) {
  const json& rec = s.at("recommended_reduced");
  std::string h = "<h2>Verdict</h2>";
  if (rec.is_object())
    h += "<p>Recommended reduced setting: <b>" + H(str(rec, "label")) + "</b>, " + H(cost(s, d(rec, "wall_s"))) +
         ". " + speedup_sentence(s) + "</p>";
  else
    h += fmt::format("<p class=warn>No reduced run reached the target of {} on {}.</p>",
                     pct(d(s, "matched_error_target")), H(chosen_on_words(str(s, "headline_quantity"))));
  h += thresholds_line(s);
  // Without a recommended setting there is no setting to read errors on (a table of n/a "at the
  // recommended setting" said nothing): the runs' own errors are in the tables below.
  if (rec.is_object()) h += verdict_rows(s);
  h += baselines_rows(s) + error_budget(s);
  return h;
}

std::string headline(const json& s) {
  // A failed validation says so first: the CLI prints this paragraph alone (a tutorial scene that
  // never settles printed a speedup without the word FAIL).
  std::string out;
  if (str(s, "status") == "fail") {
    std::string why;
    for (const auto& f : s.value("failures", json::array()))
      if (f.is_string()) why += (why.empty() ? "" : "; ") + f.get<std::string>();
    out += "FAIL: " + (why.empty() ? std::string("see the report") : why) + ". ";
  }
  const std::string Q = str(s, "headline_quantity");
  const json& rec = s.at("recommended_reduced");
  const json& full = s.value("recommended_full", json(nullptr));
  const json& speedup = s.value("recommended_speedup", json(nullptr));
  if (rec.is_object() && speedup.is_number() && full.is_object() && !full_as_accurate(s, rec, full)) {
    out += fmt::format(
        "On this machine ({}), the recommended reduced setting of '{}' ({}) takes {}; no full-model run of the "
        "ladder was as accurate on all of {} (reduced {}); its most accurate ({}, {}) takes {}: at least {}× "
        "faster at equal error. ",
        str(s, "machine"), str(s, "scene"), str(rec, "label"), cost(s, d(rec, "wall_s")), chosen_on_words(Q),
        chosen_errors(rec, Q), str(full, "label"), chosen_errors(full, Q), secs(d(full, "wall_s")),
        num(speedup.get<double>(), "{:.3g}"));
    out += extraction_sentence(s, rec, full);
  } else if (rec.is_object() && speedup.is_number() && full.is_object()) {
    out += fmt::format(
        "On this machine ({}), the recommended reduced setting of '{}' ({}) takes {} against {} for Simbody "
        "forward dynamics ({}, the cheapest full-model run at equal or better error on {}: reduced {}, full {}): "
        "{}× faster. ",
        str(s, "machine"), str(s, "scene"), str(rec, "label"), cost(s, d(rec, "wall_s")), secs(d(full, "wall_s")),
        str(full, "label"), chosen_on_words(Q), chosen_errors(rec, Q), chosen_errors(full, Q),
        num(speedup.get<double>(), "{:.3g}"));
    out += extraction_sentence(s, rec, full);
  } else if (rec.is_object() && speedup.is_number()) {
    out += fmt::format(
        "On this machine ({}), the recommended reduced setting of '{}' ({}) takes {}; no run of the full-model "
        "ladder was as accurate on {}, and it is {}× faster than the reference. ",
        str(s, "machine"), str(s, "scene"), str(rec, "label"), cost(s, d(rec, "wall_s")), chosen_on_words(Q),
        num(speedup.get<double>(), "{:.3g}"));
  } else if (rec.is_object()) {
    out += fmt::format("The recommended reduced setting of '{}' is {}; no speedup is claimed (none in the "
                       "summary). ",
                       str(s, "scene"), str(rec, "label"));
  } else {
    out += fmt::format("No reduced run of '{}' reached the target of {} of the peaks of {}: no setting is "
                       "recommended and no speedup is claimed. ",
                       str(s, "scene"), pct(d(s, "matched_error_target")), chosen_on_words(Q));
  }
  if (rec.is_object()) {
    const std::string others = other_errors(s, rec);
    if (!others.empty()) out += "At that setting the errors are " + pct(error_of(rec, "qdot")) + " for the speed" +
                                others + ". ";
  }
  return out + reference_sentence(s);
}

// What the default grid's check found (summary.json default_grid_check, validate/harness/grid_check.hpp):
// the scene's run on that grid against the run on half of it.
std::string grid_check_sentence(const json& s) {
  const json& c = s.value("default_grid_check", json(nullptr));
  if (!c.is_object() || !c.value("grid_deg", json(nullptr)).is_number()) return "";
  const double g = c["grid_deg"].get<double>();
  const auto change = c.value("change", json(nullptr));
  const std::string column = c.value("column", std::string());
  if (c.value("verified", false) && change.is_number() && c.value("finer_grid_deg", json(nullptr)).is_number())
    return H(fmt::format(" That grid was checked as rdyn simulate checks it: the scene's run on it changes {} by {} of "
                         "its peak on the {:g}° table.",
                         column, pct(change.get<double>()), c["finer_grid_deg"].get<double>()));
  if (const std::string why = c.value("not_compared", std::string()); !why.empty())
    return H(fmt::format(" That grid's run could not be compared with one on half of it: {}.", why));
  if (change.is_number())
    return H(fmt::format(" That grid's run has not converged: {} still changed by {} of its peak between the {:g}° "
                         "and {:g}° tables (more than {}), so its errors above are the measure.",
                         column, pct(change.get<double>()), c.value("coarser_grid_deg", 0.0), g,
                         pct(c.value("max_change", 5e-4))));
  return "";
}

std::string showcase_note(const json& s) {
  const json& sc = s.value("showcase_reduced", json(nullptr));
  if (!sc.is_object()) return "";
  // Summaries written before the default grid was recorded drew the 10° table.
  return "<p>The reduced run drawn is the " + H(fmt::format("{:g}", default_grid_deg(s).value_or(10.0))) +
         "° table at the default settings (" + H(str(sc, "label")) +
         "); its errors are " + H(pct(error_of(sc, "qdot")) + " for the speed" + other_errors(s, sc)) +
         ". The recommended setting's errors are in the verdict." + grid_check_sentence(s) + "</p>";
}

std::string matched_target_note(const json& s) {
  const json& mf = s.value("matched_full", json(nullptr));
  const json& mr = s.value("matched_reduced", json(nullptr));
  const std::string Q = str(s, "headline_quantity");
  if (!s.value("speedup_at_matched_error", json(nullptr)).is_number() || !mf.is_object() || !mr.is_object())
    return fmt::format("<p>At the matched-error target ({} of the peak of the {}) no full run of the ladder, or no "
                       "reduced run as accurate, was found: no speedup is claimed there.</p>",
                       pct(d(s, "matched_error_target")), H(quantity_words(Q)));
  return fmt::format("<p>At the matched-error target ({} of the peak of the {}): the cheapest full run within it, "
                     "{} ({}, error {}), against the cheapest reduced run at equal or better error, {} ({}, error "
                     "{}): {}× faster.</p>",
                     pct(d(s, "matched_error_target")), H(quantity_words(Q)), H(str(mf, "label")),
                     H(secs(d(mf, "wall_s"))), pct(error_of(mf, Q)), H(str(mr, "label")), H(secs(d(mr, "wall_s"))),
                     pct(error_of(mr, Q)), num(d(s, "speedup_at_matched_error"), "{:.3g}"));
}

}  // namespace rdyn::validate
