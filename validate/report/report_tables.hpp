// Pieces of the validation report's HTML drawn from summary.json (validate/report/report.cpp): the
// page head, the acceptance-threshold, run and extraction tables, and the formatting every piece
// shares (numbers never "nan": "n/a"; scene text escaped).
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace rdyn::validate {

namespace report_format {
using json = nlohmann::json;
// A number of the summary; NaN for null or a missing key ("not measured").
double d(const json& j, const char* key);
// A text of the summary; empty for null or a missing key.
std::string str(const json& j, const char* key);
// A run's largest error of quantity q relative to its peak; NaN when it has none.
double error_of(const json& run, const std::string& q);
// Scene-given text in HTML.
std::string H(const std::string& s);
// A number in `spec`, or "n/a" when the summary has none.
std::string num(double x, const char* spec = "{:g}");
std::string pct(double x);
std::string secs(double s);
// A cost for the run as simulated, and per simulated second only when at least a second was
// simulated (summary "per_second_measured").
std::string cost(const json& s, double wall_s);
// A compared quantity in words ("speed of the independent coordinate", "knee force").
std::string quantity_words(const std::string& q);
// What the errors were taken over: the steady revolutions, or the whole run.
std::string compared_over(const json& s);
// A {"names", "rows"} table of the summary as CSV (names quoted, numbers %.10g, null empty):
// every figure's data file.
std::string table_csv(const json& t);
// Whether q is one of the summary's joint outputs (reactions, shaking, joint motion).
bool is_joint_output(const json& s, const json& q);
// The grid the default thresholds and figure 2 are on (summary.json's default_grid_deg); empty
// for a summary written before it was recorded.
std::optional<double> default_grid_deg(const json& s);
// The first value of a hand-edited summary that `rdyn validate` could not have written, as
// "path: value why" ("recommended_speedup: \"fast\" is not a number", "runs[3].steps: 1e+300 is
// not a count", "duration_s: -3 is negative", a number beyond ±1e100, a threshold whose pass
// contradicts its error and limit); empty when there is none. The report would render such a
// value as "not measured", "inf", "-5× faster" or a wrong verdict, exit 0.
std::string find_non_number(const json& s);
// The first record of a hand-edited summary the report cannot draw truthfully, as "path: why":
// `runs` a non-empty list, each run with its text label, a model validate writes (full, reduced,
// mujoco: another vanished from the figures) and its errors; `verdicts` a list, each with its
// quantity, target, error and whether within it (a renamed key read as "above target").
// Empty when every record is whole.
std::string find_malformed_record(const json& s);
}  // namespace report_format

// <!DOCTYPE html> … <body>: the title naming the scene and the page's style.
std::string html_head(const std::string& scene);
// The thresholds with their verdicts ("" when the summary has none).
std::string thresholds_table(const nlohmann::json& summary);
// Every run with its cost and errors, the Pareto front starred, stopped runs with their reason.
std::string runs_table(const nlohmann::json& summary);
// The extractions' grids, points, kinetostatic calls and times.
std::string extraction_table(const nlohmann::json& summary);

}  // namespace rdyn::validate
