#include "validate/harness/thresholds.hpp"

#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"
#include "validate/harness/harness.hpp"
#include "tests/validate/harness/run_records.hpp"

namespace rdyn::validate {
namespace {

using test::record;

TEST(Thresholds, JudgedOnTheMatchingTightRun) {
  std::vector<RunRecord> runs{record("reduced", 1e-3, {{"qdot", 4e-3}}),
                              record("reduced", 1e-3, {{"qdot", 6e-3}}),
                              record("reduced", 1e-3, {{"qdot", 1e-4}})};
  runs[0].tolerance = 1e-10;  // the tight fourier run at 10°: the one judged
  runs[1].tolerance = 1e-8;   // same grid, looser: not judged
  runs[2].tolerance = 1e-10, runs[2].interpolation = "cubic";  // other interpolation
  const models::Threshold th{"qdot", 10.0, "", 5e-3};
  auto t = judge_threshold(th, runs, 1e-10);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->error, 4e-3);
  EXPECT_TRUE(t->pass);
  EXPECT_EQ(t->run, runs[0].label());
  // The cubic run when the threshold names cubic; a tighter limit fails.
  t = judge_threshold({"qdot", 10.0, "cubic", 5e-5}, runs, 1e-10);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->error, 1e-4);
  EXPECT_FALSE(t->pass);
  // A grid outside the ladder: no run to judge on (the harness runs it).
  EXPECT_FALSE(judge_threshold({"qdot", 7.5, "", 1.0}, runs, 1e-10));
}

TEST(Thresholds, AStoppedRunOrAMissingQuantityFails) {
  RunRecord stopped = record("reduced", 1e-3, {});
  stopped.failure = "diverged";
  const auto t = judge_threshold_on({"qdot", 10.0, "", 1e9}, stopped);
  EXPECT_FALSE(t.pass);
  EXPECT_TRUE(std::isinf(t.error));
  EXPECT_NE(t.run.find("(stopped: diverged)"), std::string::npos) << t.run;  // the failure says why
  // A stopped run as the harness records it (every quantity +∞, peak 0) is not read as a
  // reference whose peak is 0.
  mark_stopped(stopped, "m1 not positive", {"qdot"});
  const auto m = judge_threshold_on({"qdot", 10.0, "", 1e9}, stopped);
  EXPECT_TRUE(std::isinf(m.error));
  EXPECT_EQ(m.run.find("peak"), std::string::npos) << m.run;
}

TEST(Thresholds, ASceneWithoutThresholdsIsJudgedOnTheDefaults) {
  // Without defaults a validation whose every reduced run was 176 % off passed: nothing was
  // judged. The defaults cover every judged quantity but the mean speed, on the default grid.
  auto scene = models::load_scene("fourbar");
  ASSERT_TRUE(scene.validation.thresholds.empty());  // the shipped four-bar declares none
  const std::vector<std::string> judged{"qdot", scene.outputs.constraint_forces[0].name, "R_crank_x", "mean_qdot"};
  const auto th = thresholds_of(scene, judged, 2.5);
  ASSERT_EQ(th.size(), 3u);
  EXPECT_EQ(th[0].quantity, "qdot");
  EXPECT_EQ(th[1].quantity, scene.outputs.constraint_forces[0].name);
  EXPECT_EQ(th[2].quantity, "R_crank_x");  // a joint output: a scene passed while its reactions missed
  for (const auto& t : th) {
    EXPECT_EQ(t.grid_deg, 2.5);
    EXPECT_EQ(t.max_error, kDefaultThresholdMaxError);
  }
  // A run 176 % off fails them; a declared threshold replaces them all.
  std::vector<RunRecord> runs{record("reduced", 1e-3, {{"qdot", 1.76}})};
  runs[0].tolerance = 1e-10;
  runs[0].grid_deg = 2.5;
  const auto t = judge_threshold(th[0], runs, 1e-10);
  ASSERT_TRUE(t);
  EXPECT_FALSE(t->pass);
  scene.validation.thresholds = {{"qdot", 5.0, "", 0.01}};
  ASSERT_EQ(thresholds_of(scene, judged, 2.5).size(), 1u);
  EXPECT_EQ(thresholds_of(scene, judged, 2.5)[0].grid_deg, 5.0);
}

}  // namespace
}  // namespace rdyn::validate
