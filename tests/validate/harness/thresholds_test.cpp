#include "validate/harness/thresholds.hpp"

#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"
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
}

TEST(Thresholds, ASceneWithoutThresholdsIsJudgedOnTheDefaults) {
  // Without defaults a validation whose every reduced run was 176 % off passed: nothing was
  // judged. The defaults cover the speed and every requested constraint force.
  auto scene = models::load_scene("fourbar");
  ASSERT_TRUE(scene.validation.thresholds.empty());  // the shipped four-bar declares none
  const auto th = thresholds_of(scene);
  ASSERT_EQ(th.size(), 1 + scene.outputs.constraint_forces.size());
  EXPECT_EQ(th[0].quantity, "qdot");
  EXPECT_EQ(th[1].quantity, scene.outputs.constraint_forces[0].name);
  for (const auto& t : th) {
    EXPECT_EQ(t.grid_deg, kDefaultThresholdGrid_deg);
    EXPECT_EQ(t.max_error, kDefaultThresholdMaxError);
  }
  // A run 176 % off fails them; a declared threshold replaces them all.
  std::vector<RunRecord> runs{record("reduced", 1e-3, {{"qdot", 1.76}})};
  runs[0].tolerance = 1e-10;
  const auto t = judge_threshold(th[0], runs, 1e-10);
  ASSERT_TRUE(t);
  EXPECT_FALSE(t->pass);
  scene.validation.thresholds = {{"qdot", 5.0, "", 0.01}};
  ASSERT_EQ(thresholds_of(scene).size(), 1u);
  EXPECT_EQ(thresholds_of(scene)[0].grid_deg, 5.0);
}

}  // namespace
}  // namespace rdyn::validate
