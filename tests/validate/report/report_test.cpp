// The report is rendered from summary.json alone, escapes what a scene gave, and puts the
// verdicts first.
#include "validate/report/report.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tests/validate/run_rdyn.hpp"
#include "tests/validate/harness/validation_fixture.hpp"
#include "validate/harness/summary.hpp"
#include "models/scene_write.hpp"
#include "models/scene_yaml.hpp"
#include <functional>

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

TEST(Report, ReRenderedFromASavedSummaryIsTheSame) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_report_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  render_report(summary_json(test::synthetic_validation()), (dir / "a").string());
  // Only the saved summary goes into the second rendering.
  const auto saved = nlohmann::json::parse(test::slurp(dir / "a" / "summary.json"));
  render_report(saved, (dir / "b").string());
  for (const char* f : {"report.html", "runs.csv", "compare.csv", "params.csv", "params_dense.csv",
                        "pareto.gp", "convergence.csv", "summary.json"})
    EXPECT_EQ(test::slurp(dir / "a" / f), test::slurp(dir / "b" / f)) << f;
  const std::string html = test::slurp(dir / "b" / "report.html");
  EXPECT_EQ(html.find("could not be rendered"), std::string::npos)
      << test::slurp(dir / "b" / "gnuplot.log");
  size_t svgs = 0;
  for (size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 1))
    ++svgs;
  EXPECT_EQ(svgs, 4u);
  // params.csv: the 12 samples and the first again at 360°.
  const std::string params = test::slurp(dir / "b" / "params.csv");
  EXPECT_EQ(std::count(params.begin(), params.end(), '\n'), 14);
  EXPECT_NE(params.find("\n360,2,0.25\n"), std::string::npos) << params;
  // runs.csv: one row per run plus the header; the stopped run keeps its reason.
  const std::string runs = test::slurp(dir / "b" / "runs.csv");
  EXPECT_EQ(std::count(runs.begin(), runs.end(), '\n'), 6);
  EXPECT_NE(runs.find("diverged at t = 0.5 s"), std::string::npos);
  fs::remove_all(dir);
}

TEST(Report, VerdictsFirstRunsFoldedSceneTextEscaped) {
  const auto s = summary_json(test::synthetic_validation());
  const std::string html = render_html(s, {{"params", "<svg id=p></svg>"}});
  const size_t verdict = html.find("<h2>Verdict</h2>"), figure = html.find("<h2>1.");
  ASSERT_NE(verdict, std::string::npos);
  EXPECT_LT(verdict, figure);
  EXPECT_LT(html.find("full run at equal or better error"), figure);  // the speeds are on the first screen
  // F's threshold decides (it passes); every quantity is compared with the target.
  EXPECT_LT(html.find("all 1 pass", verdict), figure);
  EXPECT_LT(html.find("within target", verdict), figure);
  EXPECT_EQ(html.find("FAIL"), std::string::npos);
  const size_t details = html.find("<details><summary>All 5 runs");
  ASSERT_NE(details, std::string::npos);
  EXPECT_LT(details, html.find("diverged at t = 0.5 s"));  // the run table is folded
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_EQ(html.find("<b>markup</b>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt; &amp; co"), std::string::npos);
  EXPECT_NE(html.find("<svg id=p></svg>"), std::string::npos);
  EXPECT_NE(html.find("Figure pareto.svg could not be rendered"), std::string::npos);
  // No calibration declared: no comparison, and nothing of any one scene.
  for (const char* word : {"Calibration", "69.7", "pedal", "knee", "hip", "bicycle", "leg"})
    EXPECT_EQ(html.find(word), std::string::npos) << word;
}

TEST(Report, TheScenesComparisonComesFromTheSummary) {
  auto v = test::synthetic_validation();
  CalibrationResult c;
  c.torque_Nm = 60.0;
  c.work_per_rev_per_unit = 125.0 / 60.0;
  v.calibration = c;
  v.calibration_options.cadence_hz = 1.0;
  v.calibration_options.power_w = 125.0;
  v.compare = {{"drive_torque_Nm", 75.0, "N·m", "Someone <2001>", "Their crank was longer."}};
  const std::string html = render_html(summary_json(v), {});
  EXPECT_NE(html.find("Someone &lt;2001&gt; 75 N·m"), std::string::npos);
  EXPECT_NE(html.find("(-20 %)"), std::string::npos);  // (60 − 75) / 75
  EXPECT_NE(html.find("Their crank was longer."), std::string::npos);
  // The published value balances 125 J per revolution with 125/75 J per N·m.
  EXPECT_NE(html.find("would do 1.667 J per revolution per N·m"), std::string::npos);
}

TEST(Report, ShortRunsAreNotExtrapolatedPerSecond) {
  auto v = test::synthetic_validation();
  v.duration_s = 0.03;
  const auto s = summary_json(v);
  EXPECT_EQ(s["per_second_measured"], false);
  const std::string h = headline(s);
  EXPECT_NE(h.find("for the 0.03 s run"), std::string::npos) << h;
  EXPECT_EQ(h.find("per simulated second"), std::string::npos) << h;
  EXPECT_EQ(h.find("one second"), std::string::npos) << h;
  EXPECT_NE(h.find("whole run"), std::string::npos) << h;
  v.duration_s = 2.0;
  EXPECT_NE(headline(summary_json(v)).find("per simulated second"), std::string::npos);
}

// Headline and verdict table say what was compared: the steady revolutions, or the whole run
// (never "steady cycles" for a run that has none).
// The error budget separates output interpolation from the total and states what the
// accurate rows cost (an untimed second run), from the summary alone.
TEST(Report, ErrorBudgetNamesOutputInterpolationAndItsCost) {
  auto s = summary_json(test::synthetic_validation());
  s["error_budget"] = {{"quantity", "F"}, {"reference", 1e-9}, {"table", 2e-4},      {"integration", 3e-4},
                       {"total", 5e-4},  {"table_run", "t"},    {"output_interpolation", 2.5e-5}};
  s["recommended_reduced"]["wall_s"] = 0.002;
  s["recommended_reduced"]["compared_run_wall_s"] = 0.005;
  const std::string html = render_html(s, {});
  EXPECT_NE(html.find("Output interpolation 0.0025 %"), std::string::npos) << html;
  EXPECT_NE(html.find("2.5×"), std::string::npos) << html;
}

TEST(Report, WordingSaysWhatWasCompared) {
  auto v = test::synthetic_validation();  // compared over the whole run
  std::string html = render_html(summary_json(v), {});
  const std::string first = html.substr(0, html.find("<h2>1."));
  EXPECT_NE(first.find("max error over the whole run at the recommended setting"), std::string::npos) << first;
  EXPECT_EQ(first.find("over the steady"), std::string::npos) << first;
  EXPECT_NE(html.find("toward the end of the run"), std::string::npos);
  v.window = {1.25, 7, false, "from the second revolution"};
  html = render_html(summary_json(v), {});
  EXPECT_NE(html.find("max error over the 7 steady revolutions from t = 1.25 s"), std::string::npos);
  EXPECT_NE(headline(summary_json(v)).find("Errors are maxima over the 7 steady revolutions from t = 1.25 s"),
            std::string::npos);
  EXPECT_EQ(html.find("whole run"), std::string::npos);
  EXPECT_NE(html.find("over the last periods"), std::string::npos);
}

// `rdyn report SUMMARY --out DIR`: the same report from the saved summary; a file that is not
// a summary is bad input (exit 2, the file named, nothing written), never an internal error.
TEST(Report, CommandReRendersAndRefusesWhatIsNotASummary) {
  const fs::path dir =
      fs::temp_directory_path() / ("rdyn_report_cmd_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "a");
  render_report(summary_json(test::synthetic_validation()), (dir / "a").string());
  auto r = test::run_rdyn({"report", "a/summary.json", "--out", "b"}, dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(test::slurp(dir / "a" / "report.html"), test::slurp(dir / "b" / "report.html"));
  std::vector<std::pair<std::string, std::string>> bad{
      {"not_json.json", "{\"scene\": "},
      {"array.json", "[1, 2]"},
      {"runs_not_a_list.json", "{\"scene\": \"x\", \"runs\": 5}"},
      {"missing_keys.json", "{\"scene\": \"x\", \"runs\": []}"},
      {"wrong_types.json", "{\"scene\": 1, \"runs\": [{\"label\": 2}], \"quantities\": [3]}"}};
  // Animation records edited by hand: a scene that does not read, a frame without a pose per
  // joint, a frame time that goes back.
  const nlohmann::json frames = {{"t_s", {0.0, 0.1}}, {"q", {0.0, 0.1}}, {"q_joint", {{0.0, 0.1, 1.5}, {0.1, 0.0, 1.5}}},
                                 {"arrows", nlohmann::json::array()}, {"traces", nlohmann::json::array()}};
  const nlohmann::json record = {{"title", "t"},
                                 {"scene_yaml", models::scene_to_yaml(models::load_scene("fourbar"))},
                                 {"start", {{"t_s", 0.0}, {"q", 0.0}, {"qdot", 1.0}, {"duration_s", 0.1}}},
                                 {"frames", frames}};
  auto with_animation = [&](const std::function<void(nlohmann::json&)>& edit) {
    auto s = summary_json(test::synthetic_validation());
    s["animation"] = record;
    edit(s["animation"]);
    return s.dump();
  };
  bad.push_back({"animation_scene.json", with_animation([](nlohmann::json& a) { a["scene_yaml"] = "bodies: ["; })});
  bad.push_back({"animation_pose.json", with_animation([](nlohmann::json& a) { a["frames"]["q_joint"][1] = {0.1}; })});
  bad.push_back({"animation_time.json", with_animation([](nlohmann::json& a) { a["frames"]["t_s"] = {0.1, 0.0}; })});
  bad.push_back({"animation_null.json", with_animation([](nlohmann::json& a) { a["frames"]["q_joint"][0][0] = nullptr; })});
  for (const auto& [name, text] : bad) {
    std::ofstream(dir / name) << text;
    r = test::run_rdyn({"report", name, "--out", "c"}, dir);
    EXPECT_EQ(r.status, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find(name), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "c")) << name;
  }
  // Numbers removed by hand (null: "not measured") print as n/a, never as nan.
  auto holes = summary_json(test::synthetic_validation());
  for (const char* k : {"duration_s", "output_interval_s", "speedup_at_matched_error"})
    holes[k] = nullptr;
  holes["runs"][0]["energy_balance_residual_rel"] = nullptr;
  holes["runs"][0]["errors"]["qdot"]["max_rel"] = nullptr;
  holes["extractions"][0]["ms"] = nullptr;
  holes["baselines"][0]["speedup"] = nullptr;
  std::ofstream(dir / "holes.json") << holes.dump();
  r = test::run_rdyn({"report", "holes.json", "--out", "h"}, dir);
  EXPECT_EQ(r.status, 0) << r.err;
  std::string html = test::slurp(dir / "h" / "report.html");
  for (size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg"))
    html.erase(at, html.find("</svg>", at) + 6 - at);
  EXPECT_EQ(html.find("nan"), std::string::npos);
  EXPECT_EQ(html.find("inf"), std::string::npos);
  EXPECT_NE(html.find("n/a"), std::string::npos);
  r = test::run_rdyn({"report", "missing.json", "--out", "c"}, dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("missing.json"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate

namespace rdyn::validate {
namespace {

// Standard base64 decoding, written here as the second route to the report's encoder.
std::string from_base64(const std::string& in) {
  const std::string k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  int bits = 0;
  unsigned v = 0;
  for (char c : in) {
    if (c == '=') break;
    v = (v << 6) | static_cast<unsigned>(k.find(c));
    bits += 6;
    if (bits >= 8) out += static_cast<char>((v >> (bits - 8)) & 255), bits -= 8;
  }
  return out;
}

TEST(Report, EmbedsTheMechanismDrawingAsAnImage) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_report_svg_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const std::string& svg : {std::string("<svg><script>alert(1)</script>x</svg>"), std::string("<svg>ab</svg>"),
                                std::string("<svg>a</svg>")}) {  // the three padding cases
    auto s = summary_json(test::synthetic_validation());
    s["mechanism_svg"] = svg;
    render_report(s, dir.string());
    const std::string html = test::slurp(dir / "report.html");
    const auto at = html.find("src=\"data:image/svg+xml;base64,");
    ASSERT_NE(at, std::string::npos);
    const auto start = at + std::string("src=\"data:image/svg+xml;base64,").size();
    EXPECT_EQ(from_base64(html.substr(start, html.find('"', start) - start)), svg);
    EXPECT_EQ(html.find("<script>alert"), std::string::npos);  // never inline: an image cannot run script
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate
