#include "validate/report/report_tables.hpp"

#include <cmath>

#include <fmt/format.h>

#include "validate/io/escape.hpp"

namespace rdyn::validate {

namespace report_format {

// A number of the summary; NaN for null or a missing key ("not measured").
double d(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return NAN;
  return j[key].get<double>();
}
std::string str(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>()
                                                                : std::string();
}
double error_of(const json& run, const std::string& q) {
  if (!run.is_object() || !run.contains("errors") || !run.at("errors").contains(q)) return NAN;
  return d(run.at("errors")[q], "max_rel");
}

// Scene-given text in HTML.
std::string H(const std::string& s) { return html_escape(s); }

// A number in `spec`, or "n/a" when the summary has none (never "nan" in an output).
std::string num(double x, const char* spec) {
  return std::isfinite(x) ? fmt::format(fmt::runtime(spec), x) : "n/a";
}

std::string pct(double x) { return std::isfinite(x) ? fmt::format("{:.3g} %", 100 * x) : "n/a"; }
std::string secs(double s) {
  if (!std::isfinite(s)) return "n/a";
  if (s >= 1) return fmt::format("{:.3g} s", s);
  if (s >= 1e-3) return fmt::format("{:.3g} ms", s * 1e3);
  return fmt::format("{:.3g} µs", s * 1e6);
}

std::string cost(const json& s, double wall_s) {
  std::string c = fmt::format("{} for the {} s run", secs(wall_s), num(d(s, "duration_s")));
  if (s.value("per_second_measured", false))
    c += fmt::format(" ({} per simulated second)", secs(wall_s / d(s, "duration_s")));
  return c;
}

std::string quantity_words(const std::string& q) {
  if (q == "qdot") return "speed of the independent coordinate";
  if (q == "mean_qdot") return "mean speed of the independent coordinate";
  return q + " force";
}

// The whole run when the reference has no steady cycles (a transient, a rocking mechanism).
std::string compared_over(const json& s) {
  const auto& w = s.at("steady_window");
  if (w.value("whole_run", false)) return "over the whole run";
  // Fewer than two revolutions is what a run that never settles has (validate then fails for
  // it): those are not "steady" revolutions.
  const int n = w.value("revolutions", 0);
  if (n < 2)
    return fmt::format("over the {} revolution(s) after the start-up transient, from t = {} s (not a steady cycle)", n,
                       num(d(w, "t_start_s"), "{:.3g}"));
  return fmt::format("over the {} steady revolutions from t = {} s (after the start-up transient)", n,
                     num(d(w, "t_start_s"), "{:.3g}"));
}

std::string table_csv(const json& t) {
  std::string s;
  for (size_t c = 0; c < t.at("names").size(); ++c)
    s += (c ? "," : "") + csv_field(t.at("names")[c].get<std::string>());
  s += "\n";
  for (const auto& row : t.at("rows")) {
    for (size_t c = 0; c < row.size(); ++c)
      s += (c ? "," : "") + (row[c].is_number() ? fmt::format("{:.10g}", row[c].get<double>()) : std::string());
    s += "\n";
  }
  return s;
}

namespace {

// What `rdyn validate` writes under a key of summary.json (validate/harness/summary.cpp),
// wherever it stands; scene-named keys (force names) are not listed, the containers that hold
// them are (every leaf below them is a number).
// CountOrData: a count where it is one number (extractions' "points"), figure data where it is an
// array (convergence points, a figure's rows).
// NumericMap: an object every leaf of which is a non-negative number (errors of named forces).
enum class Kind { Any, Signed, NonNegative, Count, CountOrData, NumericMap };

Kind kind_of(const std::string& k, Kind inherited) {
  static const char* const kSigned[] = {"fx_N", "fy_N", "order", "energy_drift_per_cycle_J",
                                        "energy_balance_residual_rel"};
  static const char* const kCounts[] = {"steps", "rejected_steps", "timed_steps", "samples", "rows", "repeats",
                                        "kinetostatic_calls", "events", "excluded_between_switches"};
  static const char* const kNonNegative[] = {
      "speedup", "recommended_speedup", "speedup_at_matched_error", "extraction_ms", "matched_error_target",
      "duration_s", "wall_s", "wall_s_per_simulated_s", "compared_run_wall_s", "grid_deg", "tolerance",
      "error", "target", "max_error", "max_rel", "rms_rel", "peak", "floor", "total", "integration",
      "output_interpolation", "reference", "table", "smallest_step_s", "fixed_step_s", "fixed_steps_s", "cycles",
      "revolutions", "ms", "constraint_violation_m", "period_s", "t_start_s", "output_interval_s",
      "timed_output_interval_s"};
  for (const char* key : kSigned)
    if (k == key) return Kind::Signed;
  if (k == "points" || k == "rows") return Kind::CountOrData;
  if (k == "extraction_stages_ms" || k == "output_interpolation_max_rel") return Kind::NumericMap;
  for (const char* key : kCounts)
    if (k == key) return Kind::Count;
  for (const char* key : kNonNegative)
    if (k == key) return Kind::NonNegative;
  return inherited;
}

// Beyond this a summary's number is no measurement (the report's percentages would print inf;
// a count would overflow the integer it is read into).
constexpr double kMaxSummaryNumber = 1e100;
constexpr double kMaxSummaryCount = 1e15;

std::string bad_number_in(const json& j, const std::string& path, Kind kind) {
  auto shown = [&](const char* why) {
    std::string v = j.dump();
    if (v.size() > 40) v = v.substr(0, 40) + "…";
    return fmt::format("{}: {} {}", path, v, why);
  };
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      // Only a numeric map's kind passes to its children (errors of named forces).
      const Kind parent = kind == Kind::NumericMap ? Kind::NonNegative : Kind::Any;
      std::string found =
          bad_number_in(it.value(), path.empty() ? it.key() : path + "." + it.key(), kind_of(it.key(), parent));
      if (!found.empty()) return found;
    }
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) {
      std::string found =
          bad_number_in(j[i], fmt::format("{}[{}]", path, i), kind == Kind::CountOrData ? Kind::Signed : kind);
      if (!found.empty()) return found;
    }
  } else if (j.is_number()) {
    const double x = j.get<double>();
    if (!(std::abs(x) <= kMaxSummaryNumber)) return shown("is beyond ±1e100");
    const bool count = kind == Kind::Count || kind == Kind::CountOrData;
    if ((kind == Kind::NonNegative || kind == Kind::NumericMap || count) && x < 0) return shown("is negative");
    if (count && (x != std::floor(x) || x > kMaxSummaryCount)) return shown("is not a count");
  } else if (kind != Kind::Any && (j.is_string() || j.is_boolean())) {
    return shown("is not a number");
  }
  return "";
}

// A threshold's verdict must be what its numbers say: the report prints both.
std::string contradicted_threshold(const json& s) {
  const json& th = s.value("thresholds", json::array());
  if (!th.is_array()) return "";
  for (size_t i = 0; i < th.size(); ++i) {
    const json& t = th[i];
    if (!t.is_object() || !t.contains("pass") || !t["pass"].is_boolean()) continue;
    const double e = d(t, "error"), limit = d(t, "max_error");
    if (std::isnan(limit)) continue;
    if (t["pass"].get<bool>() != (e <= limit))
      return fmt::format("thresholds[{}].pass: {} contradicts its error {} and max_error {}", i,
                         t["pass"].get<bool>(), std::isnan(e) ? std::string("null") : fmt::format("{:g}", e),
                         fmt::format("{:g}", limit));
  }
  return "";
}

}  // namespace

std::string find_non_number(const json& s) {
  std::string found = bad_number_in(s, "", Kind::Any);
  return found.empty() ? contradicted_threshold(s) : found;
}

std::string find_malformed_record(const json& s) {
  const json* runs = s.contains("runs") ? &s["runs"] : nullptr;
  if (!runs || !runs->is_array() || runs->empty()) return "runs: missing, or not a list of runs";
  for (size_t i = 0; i < runs->size(); ++i) {
    const json& r = (*runs)[i];
    const std::string at = fmt::format("runs[{}]", i);
    if (!r.is_object()) return at + ": not a run";
    if (!r.contains("label") || !r["label"].is_string()) return at + ".label: missing or not text";
    const std::string model = r.contains("model") && r["model"].is_string() ? r["model"].get<std::string>() : "";
    if (model != "full" && model != "reduced" && model != "mujoco")
      return at + ".model: missing or not full, reduced or mujoco";
    if (!r.contains("errors") || !r["errors"].is_object()) return at + ".errors: missing or not an object";
  }
  const json* verdicts = s.contains("verdicts") ? &s["verdicts"] : nullptr;
  if (!verdicts || !verdicts->is_array()) return "verdicts: missing, or not a list";
  for (size_t i = 0; i < verdicts->size(); ++i) {
    const json& v = (*verdicts)[i];
    const std::string at = fmt::format("verdicts[{}]", i);
    if (!v.is_object()) return at + ": not a verdict";
    if (!v.contains("quantity") || !v["quantity"].is_string()) return at + ".quantity: missing or not text";
    if (!v.contains("within_target") || !v["within_target"].is_boolean())
      return at + ".within_target: missing or not true/false";
    for (const char* k : {"target", "error"})  // null: not measured (NaN)
      if (!v.contains(k) || !(v[k].is_number() || v[k].is_null())) return at + "." + k + ": missing or not a number";
  }
  // The status and its reasons agree as validate writes them: a "pass" with failures rendered
  // "pass" above a failure.
  const json* failures = s.contains("failures") ? &s["failures"] : nullptr;
  const std::string status = s.contains("status") && s["status"].is_string() ? s["status"].get<std::string>() : "";
  if (status != "pass" && status != "fail") return "status: missing or not pass or fail";
  if (!failures || !failures->is_array()) return "failures: missing or not a list";
  if ((status == "pass") != failures->empty()) return "status: " + status + " contradicts the failures listed";
  return "";
}

std::optional<double> default_grid_deg(const json& s) {
  const auto it = s.find("default_grid_deg");
  if (it == s.end() || !it->is_number()) return std::nullopt;
  return it->get<double>();
}

bool is_joint_output(const json& s, const json& q) {
  for (const auto& j : s.value("joint_output_quantities", json::array()))
    if (j == q) return true;
  return false;
}

}  // namespace report_format

using namespace report_format;

std::string html_head(const std::string& scene) {
  std::string h;
  h += "<!DOCTYPE html><html lang=en><head><meta charset='utf-8'><title>rdyn validation: " +
       H(scene) + "</title>";
  h += "<style>body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 "
       "1em;line-height:1.45;color:#222}"
       "h1{font-size:1.6em}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ccc}"
       "table{border-collapse:collapse;font-size:.85em;margin:.5em 0}td,th{border:1px solid "
       "#ccc;padding:2px 6px;"
       "text-align:right}th{background:#f3f3f3}td.l{text-align:left}.lead{font-size:1.02em;"
       "background:#f6f9ff;"
       "padding:.8em;border-left:4px solid "
       "#1f77b4}.warn{color:#a00}.pass{color:#070;font-weight:bold}.fail{color:#a00;"
       "font-weight:bold}svg{max-width:100%;height:auto}code{background:#f3f3f3;padding:0 "
       "3px}summary{cursor:pointer;"
       "font-weight:bold}</style></head><body>";
  return h;
}

std::string thresholds_table(const json& s) {
  std::string h;
  if (!s.at("thresholds").empty()) {
    h += "<h2>Acceptance thresholds</h2>";
    if (s.value("thresholds_are_defaults", false))
      h += "<p>The scene declares no thresholds: it is judged against the defaults (docs/scene-format.md, "
           "\"Validation settings\"): every compared quantity within 0.5 % of its peak on the grid rdyn's commands "
           "take for this scene" +
           (default_grid_deg(s) ? fmt::format(" ({:g}°: 10°, halved while the table does not resolve the mechanism or its run "
                                                          "changes on half the grid)",
                                              *default_grid_deg(s))
                                : std::string()) +
           ".</p>";
    h += "<table><tr><th>quantity</th><th>grid</th><th>limit</th><th>error</"
         "th><th>run</th>"
         "<th></th></tr>";
    for (const auto& t : s.at("thresholds")) {
      const bool p = t.value("pass", false);
      h += fmt::format(
          "<tr><td class=l>{}</td><td>{}°</td><td>{}</td><td>{}</td><td class=l>{}</td><td "
          "class={}>{}</td>"
          "</tr>",
          H(str(t, "quantity")), num(d(t, "grid_deg")), pct(d(t, "max_error")), pct(d(t, "error")),
          H(str(t, "run")), p ? "pass" : "fail", p ? "pass" : "FAIL");
    }
    h += "</table>";
  }
  return h;
}

std::string runs_table(const json& s) {
  std::string h;
  h += fmt::format(
      "<details><summary>All {} runs</summary><p>Median wall time of repeated runs (repeated until "
      "a minimum "
      "wall time) for the run as simulated; errors are maxima over the compared window relative to "
      "the "
      "reference's peak (RMS in <code>runs.csv</code>). ★: on the Pareto front of its model.</p>"
      "<table><tr><th>run</th><th>wall time</th><th>repeats</th><th>steps</th><th>energy "
      "residual</th>",
      s.at("runs").size());
  for (const auto& q : s.at("quantities")) h += "<th>" + H(q.get<std::string>()) + "</th>";
  h += "</tr>";
  for (const auto& r : s.at("runs")) {
    if (!str(r, "failure").empty()) {
      h += fmt::format("<tr><td class=l>{}</td><td class=l colspan={}>stopped: {}</td></tr>",
                       H(str(r, "label")), 4 + s.at("quantities").size(), H(str(r, "failure")));
      continue;
    }
    h += fmt::format("<tr><td class=l>{}{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td>",
                     r.value("pareto", false) ? "★ " : "", H(str(r, "label")), secs(d(r, "wall_s")),
                     r.value("repeats", 0), r.value("steps", 0L),
                     num(d(r, "energy_balance_residual_rel"), "{:.1e}"));
    for (const auto& q : s.at("quantities"))
      h += "<td>" + num(error_of(r, q.get<std::string>()), "{:.2e}") + "</td>";
    h += "</tr>";
  }
  h += "</table></details>";
  return h;
}

std::string extraction_table(const json& s) {
  std::string h;
  h += "<h2>Extraction "
       "cost</h2><table><tr><th>grid</th><th>points</th><th>kinetostatic calls</th>"
       "<th>time</th></tr>";
  for (const auto& e : s.at("extractions"))
    h += fmt::format("<tr><td>{}°</td><td>{}</td><td>{}</td><td>{} ms</td></tr>",
                     num(d(e, "grid_deg")), e.value("points", 0), e.value("kinetostatic_calls", 0L),
                     num(d(e, "ms"), "{:.3g}"));
  h += "</table>";
  return h;
}

}  // namespace rdyn::validate
