// Peers (issue #11): `rdyn export-mjcf` end to end, and the initial joint state both engines
// start from.
#include "validate/harness/peers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "engine/mujoco_peer.hpp"
#include "models/scene_yaml.hpp"
#include "tests/validate/run_rdyn.hpp"
#include "tests/validate/harness/run_records.hpp"
#include "tests/validate/harness/validation_fixture.hpp"
#include "validate/cli/commands.hpp"
#include "validate/report/report.hpp"
#include "validate/harness/summary.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

class ExportMjcfCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rdyn-peers-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  test::RdynRun rdyn(const std::vector<std::string>& args) { return test::run_rdyn(args, dir_); }
  fs::path dir_;
};

TEST_F(ExportMjcfCli, WritesTheSceneAndRefusesBadInputWithStatus2) {
  auto r = rdyn({"export-mjcf", "fourbar", "--out", "fourbar.xml"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string xml = test::slurp(dir_ / "fourbar.xml");
  EXPECT_EQ(xml.rfind("<mujoco model=\"fourbar\">", 0), 0u) << xml;
  EXPECT_NE(xml.find("<connect name=\"loop_C\" body1=\"coupler\" body2=\"rocker\""), std::string::npos);
  // A re-run replaces rdyn's own file; a foreign file is kept unless --force.
  EXPECT_EQ(rdyn({"export-mjcf", "fourbar", "--out", "fourbar.xml", "--timestep", "2e-4"}).status, 0);
  EXPECT_NE(test::slurp(dir_ / "fourbar.xml").find("timestep=\"0.00020000000000000001\""), std::string::npos);
  { std::ofstream(dir_ / "mine.xml") << "<robot/>"; }
  r = rdyn({"export-mjcf", "fourbar", "--out", "mine.xml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(test::slurp(dir_ / "mine.xml"), "<robot/>");
  // Standard output by default.
  r = rdyn({"export-mjcf", "bicycle", "--fold"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("<body name=\"flywheel\""), std::string::npos);  // folded into the crank
  EXPECT_NE(r.out.find("only while joint 'hip_r' turns positively"), std::string::npos);
  // Numbers and names checked before any work.
  r = rdyn({"export-mjcf", "fourbar", "--timestep", "0", "--out", "x.xml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--timestep"), std::string::npos) << r.err;
  EXPECT_EQ(rdyn({"export-mjcf", "fourbar", "--timestep", "nan", "--out", "x.xml"}).status, 2);
  EXPECT_EQ(rdyn({"export-mjcf", "fourbar", "--integrator", "implicit", "--out", "x.xml"}).status, 2);
  r = rdyn({"export-mjcf", "fourbar", "--set", "bodies.crank.mass_kg=-1", "--out", "x.xml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("mass_kg"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.xml"));
}

// The assembled state closes the four-bar's loop: the rocker's tip meets the coupler's (closed
// form of the loop condition), and the rates satisfy its time derivative.
TEST(InitialJointState, ClosesTheLoopOfTheFourBar) {
  const auto s = models::load_scene("fourbar");
  const auto st = calc_initial_joint_state(s);
  ASSERT_EQ(st.q.size(), 3u);
  EXPECT_NEAR(st.q[0], s.initial.q, 1e-12);
  EXPECT_NEAR(st.u[0], s.initial.qdot, 1e-12);
  const double a = st.q[0], b = st.q[0] + st.q[1], c = st.q[2];  // crank, coupler, rocker angles
  EXPECT_NEAR(0.08 * std::cos(a) + 0.28 * std::cos(b), 0.30 + 0.20 * std::cos(c), 1e-10);
  EXPECT_NEAR(0.08 * std::sin(a) + 0.28 * std::sin(b), 0.20 * std::sin(c), 1e-10);
  const double da = st.u[0], db = st.u[0] + st.u[1], dc = st.u[2];
  EXPECT_NEAR(-0.08 * std::sin(a) * da - 0.28 * std::sin(b) * db, -0.20 * std::sin(c) * dc, 1e-9);
}

// The peer's speedup: its cheapest run within the target against the cheapest reduced run as
// accurate, each ladder on its own; a failed validation claims nothing.
TEST(AnalysePeers, SpeedupPerLadderAtMatchedError) {
  ValidationResult v;
  v.headline_quantity = "F";
  v.matched_target = 1e-3;
  v.reference_change.samples = 100;
  v.runs = {test::record("full", 1.0, {{"F", 1e-4}}), test::record("reduced", 0.004, {{"F", 7e-4}}),
            test::record("reduced", 0.001, {{"F", 2e-4}})};
  PeerLadder euler;
  euler.engine = "mujoco";
  euler.runs = {test::record("mujoco", 0.3, {{"F", 1e-4}}), test::record("mujoco", 0.03, {{"F", 8e-4}}),
                test::record("mujoco", 0.003, {{"F", 1e-2}})};
  PeerLadder none = euler;
  none.runs = {test::record("mujoco", 0.003, {{"F", 1e-2}})};  // never within the target
  v.peers = {euler, none};
  analyse_peers(v);
  EXPECT_EQ(v.peers[0].matched_peer, 1);
  EXPECT_EQ(v.peers[0].matched_reduced, 2);  // cheaper and more accurate than run 1
  ASSERT_TRUE(v.peers[0].speedup_at_matched_error);
  EXPECT_DOUBLE_EQ(*v.peers[0].speedup_at_matched_error, 0.03 / 0.001);
  EXPECT_TRUE(v.peers[0].runs[2].pareto);
  EXPECT_FALSE(v.peers[1].speedup_at_matched_error);
  v.fail("a threshold missed");
  analyse_peers(v);
  EXPECT_FALSE(v.peers[0].speedup_at_matched_error);
}

// The peers' series, speedup and "how" are rendered from summary.json alone; text from the
// summary is escaped for gnuplot and HTML (a hand-edited summary is input like any other).
TEST_F(ExportMjcfCli, PeersAreRenderedFromTheSummaryAlone) {
  ValidationResult v = test::synthetic_validation();
  PeerLadder p;
  p.engine = "mujoco'<b>";
  p.integrator = "euler";
  p.how = "how <i>it</i> ran";
  p.runs = {test::record("mujoco", 0.03, {{"qdot", 1e-4}, {v.headline_quantity, 8e-4}}),
            test::record("mujoco", 0.3, {{"qdot", 1e-5}, {v.headline_quantity, 1e-4}})};
  p.runs[0].fixed_step_s = 1e-3;
  p.runs[1].fixed_step_s = 1e-4;
  for (auto& r : p.runs) r.integrator = "euler";
  p.speedup_at_matched_error = 123.0;
  p.matched_peer = 0;
  p.matched_reduced = 0;
  v.peers = {p};
  v.full_timing = "timed with one output";
  const auto s = summary_json(v);
  ASSERT_EQ(s.at("peers").size(), 1u);
  EXPECT_EQ(s.at("peers")[0].at("runs")[1].at("fixed_step_s").get<double>(), 1e-4);
  EXPECT_EQ(s.at("peers")[0].at("speedup_at_matched_error").get<double>(), 123.0);
  fs::create_directories(dir_ / "r");
  render_report(s, (dir_ / "r").string());
  EXPECT_EQ(test::slurp(dir_ / "r" / "pareto_peer0.csv"),
            "wall_s,error,label\n0.03,0.0008,mujoco euler h=1 ms\n0.3,0.0001,mujoco euler h=0.1 ms\n");
  const std::string gp = test::slurp(dir_ / "r" / "pareto.gp");
  EXPECT_NE(gp.find("title 'mujoco''<b> euler (fixed steps)'"), std::string::npos) << gp;
  const std::string html = test::slurp(dir_ / "r" / "report.html");
  EXPECT_NE(html.find("how &lt;i&gt;it&lt;/i&gt; ran"), std::string::npos);
  EXPECT_NE(html.find("is 123× faster than mujoco&#39;&lt;b&gt;"), std::string::npos);
  EXPECT_NE(html.find("timed with one output"), std::string::npos);
}

TEST_F(ExportMjcfCli, PeersOptionNeedsMujocoAtBuildTime) {
  auto r = rdyn({"validate", "fourbar", "--quick", "--peers", "bullet", "--out", "v"});
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(dir_ / "v"));
  r = rdyn({"validate", "fourbar", "--quick", "--peers", "mujoco", "--peers", "mujoco", "--out", "v"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("given twice"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "v"));
  if (engine::mujoco_available()) {
    EXPECT_NO_THROW(check_peers({"mujoco"}));
    return;
  }
  EXPECT_THROW(check_peers({"mujoco"}), ArgumentError);
  r = rdyn({"validate", "fourbar", "--quick", "--peers", "mujoco", "--out", "v"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("MuJoCo was not found"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "v"));
}

// A validation duration that the output interval does not divide: `simulate` ends on a last row
// at the duration, but the MuJoCo peer fills each output interval with whole steps and runs are
// compared row by row, so validation spans the whole intervals (1.0005 s at 2 ms: 1 s).
TEST_F(ExportMjcfCli, ValidateWithPeersSpansWholeOutputIntervals) {
  if (!engine::mujoco_available()) GTEST_SKIP() << "rdyn was built without MuJoCo";
  const auto r = rdyn({"validate", "fourbar", "--quick", "--peers", "mujoco", "--set", "validation.duration_s=1.0005",
                       "--out", "v"});
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  const auto s = nlohmann::json::parse(test::slurp(dir_ / "v" / "summary.json"));
  EXPECT_NEAR(s.at("duration_s").get<double>(), 1.0, 1e-12);
  for (const auto& p : s.at("peers"))
    for (const auto& run : p.at("runs")) EXPECT_FALSE(run.contains("failure")) << run.dump();
}

// End to end: MuJoCo's two ladders in summary.json and the figure's data; the full model timed
// without the output grid (fewer steps than on the grid), and the report says how.
TEST_F(ExportMjcfCli, ValidateWithMujocoPeersWritesLaddersAndFairBaselines) {
  if (!engine::mujoco_available()) GTEST_SKIP() << "rdyn was built without MuJoCo";
  const auto r = rdyn({"validate", "fourbar", "--quick", "--peers", "mujoco", "--out", "v"});
  ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;
  const auto s = nlohmann::json::parse(test::slurp(dir_ / "v" / "summary.json"));
  ASSERT_EQ(s.at("peers").size(), 2u);
  const std::string q = s.at("headline_quantity");
  for (const auto& p : s.at("peers")) {
    EXPECT_EQ(p.at("engine"), "mujoco");
    ASSERT_EQ(p.at("runs").size(), 1u);  // quick: the period/1000 step
    const auto& run = p.at("runs")[0];
    EXPECT_EQ(run.at("model"), "mujoco");
    EXPECT_GT(run.at("wall_s").get<double>(), 0.0);
    // The period/1000 step, shortened to fill the 2 ms outputs with whole steps.
    const double h = engine::calc_peer_step(s.at("time_scale").at("period_s").get<double>() / 1000, 0.002);
    EXPECT_NEAR(run.at("fixed_step_s").get<double>(), h, 1e-15);
    EXPECT_EQ(run.at("timed_steps").get<long>(), std::lround(3.0 / h));
    // The four-bar has no steady cycle (its motion decays), so the whole run is compared, t = 0
    // included, where MuJoCo's constraint force lacks the J̇·q̇ term (engine/mujoco_peer.hpp):
    // measured 0.155 for both integrators, set by that first sample.
    EXPECT_LT(run.at("errors").at(q).at("max_rel").get<double>(), 0.3);
  }
  EXPECT_TRUE(fs::exists(dir_ / "v" / "pareto_peer0.csv"));
  EXPECT_NE(test::slurp(dir_ / "v" / "pareto.gp").find("pareto_peer1.csv"), std::string::npos);
  for (const auto& run : s.at("runs")) {
    if (run.at("model") != "full" || run.contains("failure")) continue;
    EXPECT_EQ(run.at("timed_output_interval_s").get<double>(), s.at("duration_s").get<double>());
    EXPECT_LT(run.at("timed_steps").get<long>(), run.at("steps").get<long>());  // the grid capped the steps
  }
  const std::string html = test::slurp(dir_ / "v" / "report.html");
  EXPECT_NE(html.find("timed with one output at the end"), std::string::npos);
  EXPECT_NE(html.find("MuJoCo"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
