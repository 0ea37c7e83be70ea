// The report's tables and formatting (validate/report/report_tables.cpp): numbers the summary does
// not hold are "n/a", never "nan"; scene-given text is escaped; verdicts are classed.
#include "validate/report/report_tables.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include "tests/validate/harness/validation_fixture.hpp"
#include "validate/harness/summary.hpp"

namespace rdyn::validate {
namespace {

using nlohmann::json;
using namespace report_format;

TEST(ReportTables, MissingNumbersAreNotAvailableAndUnitsScale) {
  EXPECT_EQ(num(NAN), "n/a");
  EXPECT_EQ(pct(INFINITY), "n/a");
  EXPECT_EQ(secs(NAN), "n/a");
  EXPECT_EQ(pct(0.0123), "1.23 %");
  EXPECT_EQ(secs(2.5), "2.5 s");
  EXPECT_EQ(secs(2.5e-3), "2.5 ms");
  EXPECT_EQ(secs(2.5e-6), "2.5 µs");
  const json j = {{"a", 1.5}, {"b", nullptr}, {"t", "x"}};
  EXPECT_EQ(d(j, "a"), 1.5);
  EXPECT_TRUE(std::isnan(d(j, "b")));
  EXPECT_TRUE(std::isnan(d(j, "missing")));
  EXPECT_EQ(str(j, "t"), "x");
  EXPECT_EQ(str(j, "a"), "");
  const json run = {{"errors", {{"q", {{"max_rel", 2e-6}}}}}};
  EXPECT_EQ(error_of(run, "q"), 2e-6);
  EXPECT_TRUE(std::isnan(error_of(run, "qdot")));
}

TEST(ReportTables, ScenesTextIsEscapedAndVerdictsAreClassed) {
  const json s = {
      {"thresholds",
       {{{"quantity", "F_<b>"}, {"grid_deg", 10}, {"max_error", 0.01}, {"error", 0.02}, {"run", "r&1"}, {"pass", false}},
        {{"quantity", "q"}, {"grid_deg", 5}, {"max_error", 0.01}, {"error", 0.001}, {"run", "r2"}, {"pass", true}}}},
      {"quantities", {"q"}},
      {"runs",
       {{{"label", "<script>x</script>"}, {"wall_s", 0.002}, {"repeats", 3}, {"steps", 40},
         {"energy_balance_residual_rel", 1e-9}, {"errors", {{"q", {{"max_rel", 3e-5}}}}}, {"pareto", true}},
        {{"label", "stopped"}, {"failure", "budget <exceeded>"}}}},
      {"extractions", {{{"grid_deg", 10}, {"points", 36}, {"kinetostatic_calls", 40}, {"ms", 3.3}}}}};
  const std::string t = thresholds_table(s);
  EXPECT_NE(t.find("F_&lt;b&gt;"), std::string::npos) << t;
  EXPECT_NE(t.find("r&amp;1"), std::string::npos) << t;
  EXPECT_NE(t.find("class=fail>FAIL"), std::string::npos) << t;
  EXPECT_NE(t.find("class=pass>pass"), std::string::npos) << t;
  EXPECT_EQ(thresholds_table(json{{"thresholds", json::array()}}), "");
  const std::string r = runs_table(s);
  EXPECT_EQ(r.find("<script>"), std::string::npos) << r;
  EXPECT_NE(r.find("★ &lt;script&gt;"), std::string::npos) << r;
  EXPECT_NE(r.find("stopped: budget &lt;exceeded&gt;"), std::string::npos) << r;
  EXPECT_NE(r.find("3.00e-05"), std::string::npos) << r;
  EXPECT_NE(extraction_table(s).find("<td>36</td><td>40</td><td>3.3 ms</td>"), std::string::npos);
  EXPECT_NE(html_head("a<b").find("<title>rdyn validation: a&lt;b</title>"), std::string::npos);
}

// `rdyn report` of a hand-edited summary: a number turned into text is named by its path (it was
// read as "not measured" and rendered, exit 0); a summary as validate writes it has none, and
// scene-named keys (a force called "error_label") holding text are not numbers' keys.
TEST(ReportTables, ANumberEditedIntoTextIsFoundByItsPath) {
  json s = summary_json(test::synthetic_validation());
  EXPECT_EQ(find_non_number(s), "");
  json edited = s;
  edited["recommended_speedup"] = "fast";
  EXPECT_EQ(find_non_number(edited), "recommended_speedup: \"fast\" is not a number");
  edited = s;
  ASSERT_TRUE(edited["runs"].size() > 1);
  edited["runs"][1]["wall_s"] = true;
  EXPECT_EQ(find_non_number(edited), "runs[1].wall_s: true is not a number");
  EXPECT_EQ(find_non_number(json{{"scene", "x"}, {"labels", {{"error_label", "text"}}}}), "");
  EXPECT_EQ(find_non_number(json{{"extractions", {{{"points", {1, "2"}}}}}}),
            "extractions[0].points[1]: \"2\" is not a number");
  // Numbers validate cannot have written: a count beyond what it is read into (runs.csv printed
  // -9223372036854775808), a negative duration or speedup, 1e308 (the report printed inf), a
  // named force's interpolation error as text, and a verdict its own numbers contradict.
  for (const auto& [path, value, why] : std::vector<std::tuple<json::json_pointer, json, std::string>>{
           {json::json_pointer("/runs/1/steps"), 1e18, "runs[1].steps: 1e+18 is not a count"},
           {json::json_pointer("/runs/1/steps"), 2.5, "runs[1].steps: 2.5 is not a count"},
           {json::json_pointer("/duration_s"), -3, "duration_s: -3 is negative"},
           {json::json_pointer("/recommended_speedup"), -5, "recommended_speedup: -5 is negative"},
           {json::json_pointer("/matched_error_target"), 1e308, "matched_error_target: 1e+308 is beyond ±1e100"},
           {json::json_pointer("/runs/0/output_interpolation_max_rel/F"), "x",
            "runs[0].output_interpolation_max_rel.F: \"x\" is not a number"}}) {
    edited = s;
    edited[path] = value;
    EXPECT_EQ(find_non_number(edited), why);
  }
  edited = s;
  edited["thresholds"] = json::array({{{"quantity", "F"}, {"error", 1.0}, {"max_error", 0.005}, {"pass", true}}});
  EXPECT_EQ(find_non_number(edited), "thresholds[0].pass: true contradicts its error 1 and max_error 0.005");
  edited["thresholds"][0]["pass"] = false;
  EXPECT_EQ(find_non_number(edited), "");
}

// Records the report draws from, edited by hand (a hostile pass: each rendered with exit 0 and
// content changed): the first broken one named by its path; a whole summary has none.
TEST(ReportTables, ABrokenRunOrVerdictRecordIsFoundByItsPath) {
  const json s = summary_json(test::synthetic_validation());
  ASSERT_FALSE(s["verdicts"].empty());
  EXPECT_EQ(find_malformed_record(s), "");
  auto edited = [&](const std::function<void(json&)>& edit) {
    json e = s;
    edit(e);
    return find_malformed_record(e);
  };
  EXPECT_EQ(edited([](json& e) { e["runs"] = json::array(); }), "runs: missing, or not a list of runs");
  EXPECT_EQ(edited([](json& e) { e["runs"][1].erase("label"); }), "runs[1].label: missing or not text");
  EXPECT_EQ(edited([](json& e) { e["runs"][0]["model"] = "bogus"; }),
            "runs[0].model: missing or not full, reduced or mujoco");
  EXPECT_EQ(edited([](json& e) { e["runs"][0]["errors"] = "x"; }), "runs[0].errors: missing or not an object");
  EXPECT_EQ(edited([](json& e) { e["verdicts"] = nullptr; }), "verdicts: missing, or not a list");
  EXPECT_EQ(edited([](json& e) {
              e["verdicts"][0]["within"] = e["verdicts"][0]["within_target"];
              e["verdicts"][0].erase("within_target");
            }),
            "verdicts[0].within_target: missing or not true/false");
  EXPECT_EQ(edited([](json& e) { e["verdicts"][0].erase("target"); }), "verdicts[0].target: missing or not a number");
  EXPECT_EQ(edited([](json& e) { e["verdicts"][0]["error"] = nullptr; }), "");  // not measured: null, as written
  // A status its failures contradict (it rendered "pass" above a failure).
  EXPECT_EQ(edited([](json& e) { e["failures"] = json::array({"threshold qdot missed"}); }),
            s["status"] == "pass" ? "status: pass contradicts the failures listed" : "");
  EXPECT_EQ(edited([](json& e) { e["status"] = "fail"; e["failures"] = json::array(); }),
            "status: fail contradicts the failures listed");
  EXPECT_EQ(edited([](json& e) { e["status"] = "ok"; }), "status: missing or not pass or fail");
}

// A window of fewer than two revolutions (a run that never settles, which fails validate) is not
// called steady (the report said "the 1 steady revolutions" under a failure saying it never settles).
TEST(ReportTables, AWindowOfOneRevolutionIsNotCalledSteady) {
  json s{{"steady_window", {{"whole_run", false}, {"revolutions", 1}, {"t_start_s", 2.66}}}};
  EXPECT_EQ(compared_over(s), "over the 1 revolution(s) after the start-up transient, from t = 2.66 s (not a steady "
                              "cycle)");
  s["steady_window"]["revolutions"] = 4;
  EXPECT_EQ(compared_over(s), "over the 4 steady revolutions from t = 2.66 s (after the start-up transient)");
}

}  // namespace
}  // namespace rdyn::validate
