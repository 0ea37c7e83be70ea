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
  return fmt::format("over the {} steady revolutions from t = {} s", w.value("revolutions", 0),
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

// Keys whose values `rdyn validate` writes as numbers, arrays of numbers or null, wherever they
// stand in summary.json (validate/harness/summary.cpp); scene-named keys (force names) excluded.
bool numeric_key(const std::string& k) {
  static const char* const kKeys[] = {
      "speedup", "recommended_speedup", "speedup_at_matched_error", "extraction_ms", "matched_error_target",
      "duration_s", "wall_s", "wall_s_per_simulated_s", "compared_run_wall_s", "grid_deg", "tolerance",
      "error", "target", "max_error", "max_rel", "rms_rel", "peak", "floor", "total", "integration",
      "output_interpolation", "steps", "rejected_steps", "smallest_step_s", "fixed_step_s", "fixed_steps_s",
      "timed_steps", "samples", "cycles", "revolutions", "rows", "repeats", "ms", "kinetostatic_calls",
      "energy_balance_residual_rel", "energy_drift_per_cycle_J", "constraint_violation_m", "period_s",
      "t_start_s", "output_interval_s", "timed_output_interval_s", "fx_N", "fy_N", "order", "points"};
  for (const char* key : kKeys)
    if (k == key) return true;
  return false;
}

std::string find_non_number_in(const json& j, const std::string& path, bool numeric) {
  if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) {
      std::string found = find_non_number_in(it.value(), path.empty() ? it.key() : path + "." + it.key(),
                                             numeric_key(it.key()));
      if (!found.empty()) return found;
    }
  } else if (j.is_array()) {
    for (size_t i = 0; i < j.size(); ++i) {
      std::string found = find_non_number_in(j[i], fmt::format("{}[{}]", path, i), numeric);
      if (!found.empty()) return found;
    }
  } else if (numeric && (j.is_string() || j.is_boolean())) {
    std::string v = j.dump();
    if (v.size() > 40) v = v.substr(0, 40) + "…";
    return path + ": " + v;
  }
  return "";
}

}  // namespace

std::string find_non_number(const json& s) { return find_non_number_in(s, "", false); }

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
           "\"Validation settings\").</p>";
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
