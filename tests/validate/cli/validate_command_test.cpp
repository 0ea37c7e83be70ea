// `rdyn validate` end to end on a small suite: outputs, thresholds, verdicts, exit status, and a
// 30 ms transient.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), {});
}

// A 30 ms transient (issue #14): the shipped four-bar's geometry started from rest by a strong
// motor, about 1.5 accelerating revolutions.
constexpr const char* kTransient = R"(name: transient
ground_points: {A: [0.0, 0.0], D: [0.30, 0.0]}
bodies:
  - {name: crank,   mass_kg: 0.50, com_m: [0.04, 0], inertia_kgm2: 2.667e-4, points: {B: [0.08, 0]}}
  - {name: coupler, mass_kg: 1.20, com_m: [0.14, 0], inertia_kgm2: 7.84e-3,  points: {C: [0.28, 0]}}
  - {name: rocker,  mass_kg: 0.90, com_m: [0.10, 0], inertia_kgm2: 3.0e-3,   points: {C: [0.20, 0]}}
joints:
  - {name: crank,   type: revolute, parent: ground, parent_point: A, child: crank,   child_point: [0, 0], guess_deg: 30}
  - {name: coupler, type: revolute, parent: crank,  parent_point: B, child: coupler, child_point: [0, 0], guess_deg: 4.85}
  - {name: rocker,  type: revolute, parent: ground, parent_point: D, child: rocker,  child_point: [0, 0], guess_deg: 90.27}
loops:
  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}
independent: crank
loads:
  - {type: motor, name: motor, joint: crank, stall_torque_Nm: 150.0, no_load_speed_rad_s: 3000.0}
gravity: {enabled: true, g_m_s2: [0, -9.81]}
outputs:
  constraint_forces:
    - {name: rocker_axial, joint: rocker, direction: C}
initial: {q_deg: 30, qdot: 0.0}
simulation: {duration_s: 0.03, output_interval_s: 1.0e-4}
validation:
  thresholds: [{quantity: qdot, grid_deg: 10, max_error: 1.0e-3}]
)";

int run(const std::string& args, std::string& out) {
  FILE* p = popen((std::string(RDYN_BINARY) + " " + args + " 2>&1").c_str(), "r");
  std::array<char, 4096> buf{};
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(ValidateCommand, SuiteWritesReportsAndFailsOnAThreshold) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_suite_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "suite");
  // The four-bar with a loose threshold (passes) and an impossible one (fails), plus a broken scene.
  const std::string fourbar = std::string(RDYN_SCENES) + "/fourbar.yaml";
  std::ifstream in(fourbar);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(dir / "suite" / "a_pass.yaml") << text << "validation: {duration_s: 2, thresholds: [{quantity: qdot, grid_deg: 10, max_error: 0.05}]}\n";
  std::ofstream(dir / "suite" / "b_fail.yaml") << text << "validation: {duration_s: 2, thresholds: [{quantity: rocker_axial, grid_deg: 30, max_error: 1.0e-12}]}\n";
  std::ofstream(dir / "suite" / "c_broken.yaml") << "name: broken\nbodies: 3\n";
  std::ofstream(dir / "suite" / "d_transient.yaml") << kTransient;
  std::string out;
  const int status = run("validate --suite " + (dir / "suite").string() + " --out " + (dir / "out").string(), out);
  EXPECT_EQ(status, 1) << out;
  std::ifstream sf(dir / "out" / "summary.json");
  const auto j = nlohmann::json::parse(sf);
  ASSERT_EQ(j["scenes"].size(), 4u);
  EXPECT_EQ(j["scenes"][0]["status"], "pass");
  EXPECT_EQ(j["scenes"][1]["status"], "fail");
  EXPECT_EQ(j["scenes"][2]["status"], "error");
  EXPECT_EQ(j["scenes"][3]["status"], "pass") << j["scenes"][3].dump(1);
  // Standard error is a pipe here, not a terminal: each scene still says how it ended, in order.
  const size_t said_a = out.find("suite [1/4] a_pass: pass ("), said_b = out.find("suite [2/4] b_fail: fail ("),
               said_c = out.find("suite [3/4] c_broken: error ("), said_d = out.find("suite [4/4] d_transient: pass (");
  EXPECT_TRUE(said_a < said_b && said_b < said_c && said_c < said_d && said_d != std::string::npos) << out;
  // The index carries each scene's verdicts: the failing threshold shows as FAIL on its row.
  const std::string index = slurp(dir / "out" / "index.html");
  // The broken scene has no report: its row names it without a link to one.
  EXPECT_EQ(index.find("c_broken/report.html"), std::string::npos);
  const size_t row_b = index.find("b_fail/report.html"), row_c = index.find("<td class=l>c_broken</td>");
  ASSERT_NE(row_b, std::string::npos);
  ASSERT_NE(row_c, std::string::npos);
  EXPECT_NE(index.substr(row_b, row_c - row_b).find("rocker_axial"), std::string::npos);
  EXPECT_NE(index.substr(row_b, row_c - row_b).find("FAIL"), std::string::npos);
  for (const char* f : {"report.html", "summary.json", "params.svg", "timeseries.svg", "pareto.svg", "convergence.svg",
                        "params.gp", "compare.csv", "runs.csv"})
    EXPECT_TRUE(fs::exists(dir / "out" / "a_pass" / f)) << f;
  const std::string html = slurp(dir / "out" / "a_pass" / "report.html");
  EXPECT_EQ(html.find("could not be rendered"), std::string::npos);
  size_t svgs = 0, mechanism = 0;  // the four figures, and the animation of one cycle
  for (size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 1))
    ++(html.compare(at, 57, "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"mechanism\"") == 0 ? mechanism : svgs);
  EXPECT_EQ(svgs, 4u);
  EXPECT_EQ(mechanism, 1u);
  // The verdict table comes before the first figure and names every quantity.
  const size_t verdict = html.find("<h2>Verdict</h2>"), figure = html.find("<svg");
  ASSERT_NE(verdict, std::string::npos);
  for (const char* q : {">qdot<", ">rocker_axial<", ">mean_qdot<"}) EXPECT_LT(html.find(q, verdict), figure) << q;
  // A four-bar's report holds nothing of the bicycle (issue #14).
  for (const char* word : {"pedal", "knee", "hip torque", "69.7 N", "Two legs", "original authors", "thigh", "paper"})
    EXPECT_EQ(html.find(word), std::string::npos) << word;

  // The 30 ms transient: every run takes enough steps, none stops, the whole run is compared
  // and no cost is extrapolated to a second.
  const auto t = nlohmann::json::parse(slurp(dir / "out" / "d_transient" / "summary.json"));
  EXPECT_EQ(t["per_second_measured"], false);
  EXPECT_EQ(t["steady_window"]["whole_run"], true);
  for (const auto& r : t["runs"]) {
    EXPECT_FALSE(r.contains("failure")) << r["label"];
    EXPECT_GE(r["steps"].get<long>(), 30) << r["label"];
  }
  for (const auto& h : t["fixed_steps_s"]) EXPECT_LE(h.get<double>(), 0.03 / 100 * (1 + 1e-12));
  const std::string th = slurp(dir / "out" / "d_transient" / "report.html");
  EXPECT_EQ(th.find("per simulated second"), std::string::npos);
  EXPECT_NE(th.find("for the 0.03 s run"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace

#include "tests/validate/run_rdyn.hpp"

namespace {

// A fresh folder for one test, holding the user's leg press (tests/validate/scenes/legpress-cal.yaml)
// as legpress.yaml with `extra` appended (lines of its validation.thresholds list).
fs::path folder_with_legpress(const std::string& name, const std::string& extra) {
  const fs::path dir = fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "legpress.yaml")
      << slurp(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/legpress-cal.yaml") + extra;
  return dir;
}

// A user's leg press asks for every reaction and the shaking load (issue #23): validate compares
// each one the reduced model gives with the full model, judges a threshold on one of them, plots
// them, and names the reaction only the full model gives (the rail: a spring acts on its
// carriage). The reduced model agrees with the full one to about 1e-5 of each peak.
TEST(ValidateCommand, JointReactionsAndShakingAreComparedJudgedAndPlotted) {
  const fs::path dir =
      folder_with_legpress("rdyn_validate_joints", "    - {quantity: R_crank_x, grid_deg: 10, max_error: 1.0e-3}\n");
  rdyn::test::RunLimits limits;
  limits.time_limit_s = 600.0;
  const auto r = rdyn::test::run_rdyn({"validate", "legpress.yaml", "--quick", "--out", "v"}, dir, limits);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(slurp(dir / "v/summary.json"));
  const auto& q = s.at("quantities");
  for (const char* name : {"R_crank_x", "R_knee_y", "R_wrist_x", "shaking_M"})
    EXPECT_NE(std::find(q.begin(), q.end(), name), q.end()) << name;
  EXPECT_EQ(std::find(q.begin(), q.end(), "R_rail_x"), q.end());  // not given by the reduced model
  ASSERT_EQ(s.at("reactions_not_given").size(), 1u);
  EXPECT_EQ(s.at("reactions_not_given")[0].at("reaction"), "rail");
  bool judged = false;
  for (const auto& t : s.at("thresholds"))
    if (t.at("quantity") == "R_crank_x") {
      judged = true;
      EXPECT_LT(t.at("error").get<double>(), 1e-4);
    }
  EXPECT_TRUE(judged);
  for (const char* name : {"R_crank_x", "R_hip_y", "shaking_x"}) {
    const double e = s.at("showcase_reduced").at("errors").at(name).at("max_rel").get<double>();
    EXPECT_LT(e, 1e-4) << name;
  }
  const std::string html = slurp(dir / "v/report.html");
  EXPECT_NE(html.find("Joint reactions and shaking load"), std::string::npos);
  EXPECT_NE(html.find("Reaction rail: full model only"), std::string::npos);
  EXPECT_NE(slurp(dir / "v/joint_outputs.csv").find("R_rail_y_full"), std::string::npos);
  EXPECT_NE(slurp(dir / "v/joint_outputs.svg").find("<svg"), std::string::npos);
  fs::remove_all(dir);
}

// A threshold on a reaction only the full model gives could only fail after the whole ladder:
// refused before any work (exit 2, the threshold's field), nothing written.
TEST(ValidateCommand, AThresholdOnAFullModelOnlyReactionIsRefusedUpFront) {
  const fs::path dir =
      folder_with_legpress("rdyn_validate_full_only", "    - {quantity: R_rail_x, grid_deg: 10, max_error: 1.0e-3}\n");
  const auto r = rdyn::test::run_rdyn({"validate", "legpress.yaml", "--quick", "--out", "v"}, dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("validation.thresholds[2].quantity"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("reduced model does not give"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "v"));
  fs::remove_all(dir);
}

// `reactions: all` on the reduced model gives every reaction it can and names the others (the
// leg press's rail); a listed reaction it cannot give is still refused (exit 2, with the line).
TEST(ValidateCommand, ReactionsAllOnTheReducedModelNamesTheOnesItCannotGive) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_reactions_all_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string scene = std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/legpress-cal.yaml";
  const auto r = rdyn::test::run_rdyn({"simulate", scene, "--model", "reduced", "--duration", "0.5", "--out", "red"}, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("does not give reaction 'rail'"), std::string::npos) << r.err;
  // Once, although the default grid's check runs the model again on half the grid.
  EXPECT_EQ(r.err.find("does not give reaction 'rail'"), r.err.rfind("does not give reaction 'rail'")) << r.err;
  const std::string header = slurp(dir / "red/timeseries.csv").substr(0, 2000);
  EXPECT_NE(header.find(",R_crank_x,"), std::string::npos) << header;
  EXPECT_EQ(header.find("R_rail_"), std::string::npos) << header;
  EXPECT_EQ(nlohmann::json::parse(slurp(dir / "red/run.json")).at("reactions_not_given")[0].at("reaction"), "rail");
  std::string text = slurp(scene);
  text.replace(text.find("reactions: all"), 14, "reactions: [rail, crank]");
  std::ofstream(dir / "listed.yaml") << text;
  const auto listed =
      rdyn::test::run_rdyn({"simulate", "listed.yaml", "--model", "reduced", "--out", "listed"}, dir);
  EXPECT_EQ(listed.status, 2) << listed.err;
  EXPECT_NE(listed.err.find("cannot give the reaction of prismatic joint 'rail'"), std::string::npos) << listed.err;
  fs::remove_all(dir);
}

}  // namespace

#include "models/pose.hpp"
#include "models/scene_yaml.hpp"
#include "tests/validate/browser.hpp"
#include "validate/analysis/cycle_run.hpp"
#include "validate/analysis/mechanism_run.hpp"
#include "validate/report/cycle_animation.hpp"

namespace {

// The report animates one steady cycle of the full model (issue #26): in headless Chromium,
// report.html#t=T shows, for two times of that cycle, every joint where the full model puts it —
// the cycle re-run in this process from the start summary.json records (its state on the
// reference's last whole revolution) and placed by models::calc_pose — to 1e-9 m, the ground
// pivots on their ground points and the loop closed. `rdyn report` redraws the same animation
// from the summary alone.
TEST(ValidateCommand, ReportAnimatesOneSteadyCycleWhereTheFullModelPutsIt) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_validate_animation_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto r = rdyn::test::run_rdyn({"validate", "slider-crank", "--quick", "--out", "v"}, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto summary = nlohmann::json::parse(slurp(dir / "v/summary.json"));
  ASSERT_TRUE(summary.contains("animation"));
  const auto rec = rdyn::validate::read_animation_record(summary.at("animation"));
  const auto s = rdyn::models::load_scene("slider-crank", {});
  // The last whole revolution of the 2 s reference (the motor's steady ~48 rad/s: 0.13 s).
  EXPECT_GT(rec.start.t_s, 1.5);
  EXPECT_NEAR(rec.start.duration_s, 0.13, 0.02);
  EXPECT_LE(rec.start.t_s + rec.start.duration_s, summary.at("duration_s").get<double>() + 1e-9);
  const auto cycle = rdyn::validate::simulate_cycle(s, rec.start);
  EXPECT_NEAR(std::abs(cycle.q.back() - cycle.q.front()), 2 * M_PI, 1e-5);
  rdyn::test::Chromium browser(dir);
  for (const double t : {rec.start.t_s + 0.23 * rec.start.duration_s, rec.start.t_s + 0.71 * rec.start.duration_s}) {
    const std::string dom = browser.dump_dom(dir / "v/report.html", t);
    size_t row = 0;
    for (size_t i = 0; i < cycle.t.size(); ++i)
      if (std::abs(cycle.t[i] - t) < std::abs(cycle.t[row] - t)) row = i;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(dom, m, std::regex("<div class=\"animation\" data-t=\"([^\"]+)\"")));
    EXPECT_NEAR(std::stod(m[1]), cycle.t[row], 1e-12);
    const auto pose = rdyn::models::calc_pose(s, rdyn::validate::joint_coordinates(s, cycle, row));
    const auto joints = rdyn::test::positions(dom, "data-joint");
    ASSERT_EQ(joints.size(), s.joints.size());
    for (size_t j = 0; j < s.joints.size(); ++j) {
      EXPECT_NEAR(joints.at(s.joints[j].name).x, pose.joints[j].x, 1e-9) << s.joints[j].name << " at " << t;
      EXPECT_NEAR(joints.at(s.joints[j].name).y, pose.joints[j].y, 1e-9) << s.joints[j].name << " at " << t;
    }
    for (const auto& jt : s.joints)
      if (jt.parent == rdyn::models::kGround && jt.type == rdyn::models::JointType::Revolute) {
        EXPECT_NEAR(joints.at(jt.name).x, jt.parent_point.x, 1e-9) << jt.name;
        EXPECT_NEAR(joints.at(jt.name).y, jt.parent_point.y, 1e-9) << jt.name;
      }
    const auto loops = rdyn::test::positions(dom, "data-loop");
    for (const auto& l : s.loops)
      EXPECT_LT(std::hypot(loops.at(l.name + ".a").x - loops.at(l.name + ".b").x,
                           loops.at(l.name + ".a").y - loops.at(l.name + ".b").y),
                1e-8);
  }
  // Re-rendered from the summary alone: the same animation.
  const auto again = rdyn::test::run_rdyn({"report", "v/summary.json", "--out", "again"}, dir);
  ASSERT_EQ(again.status, 0) << again.err;
  const std::string a = slurp(dir / "v/report.html"), b = slurp(dir / "again/report.html");
  const auto frames = [](const std::string& html) {
    const auto at = html.find("<script class=\"frames\"");
    return at == std::string::npos ? std::string() : html.substr(at, html.find("</script>", at) - at);
  };
  EXPECT_FALSE(frames(a).empty());
  EXPECT_EQ(frames(a), frames(b));
  fs::remove_all(dir);
}

// A user's five-bar geared 6:1 without thresholds (issue #23): 10° misses m1 by 50 % from every
// other grid point, and validate judged it there (q̇ 61 % off: a false failure) while every other
// command refines. It is judged on the grid the commands take (1.25°), every joint output
// included, and its figure draws that grid's run.
TEST(ValidateCommand, ASceneWithoutThresholdsIsJudgedOnTheCommandsGridAndEveryJointOutput) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_validate_default_grid_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string text = slurp(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/fivebar-2to1.yaml");
  text = text.substr(0, text.find("validation:"));
  text.replace(text.find("ratio: 2.0"), 10, "ratio: 6.0");
  text.replace(text.find("q_deg: 90"), 9, "q_deg: 80");
  std::ofstream(dir / "fivebar6.yaml") << text;
  rdyn::test::RunLimits limits;
  limits.time_limit_s = 600.0;
  const auto r = rdyn::test::run_rdyn({"validate", "fivebar6.yaml", "--quick", "--out", "v"}, dir, limits);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(slurp(dir / "v/summary.json"));
  EXPECT_EQ(s.at("default_grid_deg").get<double>(), 1.25);
  EXPECT_TRUE(s.at("thresholds_are_defaults").get<bool>());
  EXPECT_TRUE(s.at("recommended_on_all_quantities").get<bool>());
  std::vector<std::string> judged;
  for (const auto& t : s.at("thresholds")) {
    judged.push_back(t.at("quantity"));
    EXPECT_EQ(t.at("grid_deg").get<double>(), 1.25);
    EXPECT_LT(t.at("error").get<double>(), 1e-4) << t.at("quantity");  // measured ≤ 5e-6
  }
  for (const char* q : {"qdot", "arm1_axial", "R_P_x", "R_fast_y", "qddot_arm2", "shaking_M"})
    EXPECT_NE(std::find(judged.begin(), judged.end(), q), judged.end()) << q;
  EXPECT_NE(s.at("showcase_reduced").at("label").get<std::string>().find("1.25°"), std::string::npos);
  const std::string html = slurp(dir / "v/report.html");
  EXPECT_NE(html.find("The reduced run drawn is the 1.25° table"), std::string::npos);
  EXPECT_NE(html.find("take for this scene (1.25°: 10°, halved"), std::string::npos);
  fs::remove_all(dir);
}

// An isosceles crank folds flat twice a turn, where the rod force has a pole: coarse tables are
// not models (m1 ≤ 0 between 30° points). Those runs are recorded as stopped with the reason and
// the validation fails with its report written (it exited 2, writing nothing).
TEST(ValidateCommand, ATableThatIsNotAModelStopsItsRunsNotTheValidation) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_validate_not_a_model_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto r = rdyn::test::run_rdyn(
      {"validate", std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/iso-crank-driven.yaml", "--quick", "--out", "v"},
      dir);
  EXPECT_EQ(r.status, 1) << r.err;
  ASSERT_TRUE(fs::exists(dir / "v/report.html")) << r.err;
  const auto s = nlohmann::json::parse(slurp(dir / "v/summary.json"));
  bool stopped = false;
  for (const auto& run : s.at("runs"))
    stopped |= run.value("failure", std::string()).find("is not positive") != std::string::npos;
  EXPECT_TRUE(stopped);
  EXPECT_NE(r.err.find("stopped:"), std::string::npos) << r.err;  // the failing threshold says why
  fs::remove_all(dir);
}

}  // namespace
