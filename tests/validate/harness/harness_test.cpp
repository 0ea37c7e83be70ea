// The harness's stages: the reference on a real scene, and the analysis stages on records.
#include "validate/harness/harness.hpp"

#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"
#include "tests/validate/harness/validation_fixture.hpp"

namespace rdyn::validate {
namespace {

TEST(Harness, ReferenceOfTheFourBar) {
  const auto scene = models::load_scene("fourbar");
  engine::FullModel full(scene);
  ValidationResult v;
  v.duration_s = 0.5;
  v.output_interval_s = 0.002;
  v.reference_tolerance = 1e-10;
  Progress quiet(false);
  run_reference(scene, full, v, quiet);
  ASSERT_EQ(v.reference.t.size(), 251u);
  EXPECT_TRUE(v.pass) << v.failure_summary();
  // Halving a 1e-10 tolerance moves the speed by far less than the 1e-3 matched-error target.
  EXPECT_LT(v.reference_change.find("qdot")->max_rel, 1e-6);
  EXPECT_GT(v.reference_change.find("qdot")->peak, 1.0);
  // The four-bar starts at 8 rad/s and does not turn three times in 0.5 s: no steady cycles.
  EXPECT_TRUE(v.window.whole_run);
  double peak = 0;
  for (double w : v.reference.qdot) peak = std::max(peak, std::abs(w));
  EXPECT_NEAR(v.time_scale.period_s, 2 * M_PI / peak, 1e-12);
  EXPECT_EQ(v.reference_run.steps, v.reference.stats.steps_taken);
}

TEST(Harness, TooFewSamplesFailAndClaimNoSpeedup) {
  const auto scene = models::load_scene("fourbar");
  engine::FullModel full(scene);
  ValidationResult v;
  v.duration_s = 0.02;  // 10 samples
  v.output_interval_s = 0.002;
  v.reference_tolerance = 1e-10;
  Progress quiet(false);
  run_reference(scene, full, v, quiet);
  EXPECT_FALSE(v.pass);
  EXPECT_NE(v.failure_summary().find("output samples"), std::string::npos);
  auto w = test::synthetic_validation();
  w.reference_change = v.reference_change;
  analyse_runs(w);
  EXPECT_GE(w.matched_full, 0);
  EXPECT_FALSE(w.speedup_at_matched_error);
}

TEST(Harness, AnalysisAndFirstScreenFromRecords) {
  auto v = test::synthetic_validation();
  v.recommended = -1;
  v.verdicts.clear();
  v.baselines.clear();
  analyse_runs(v);
  EXPECT_EQ(v.recommended, 2);
  EXPECT_EQ(v.matched_full, 1);
  EXPECT_EQ(v.matched_reduced, 2);
  ASSERT_TRUE(v.speedup_at_matched_error);
  EXPECT_DOUBLE_EQ(*v.speedup_at_matched_error, 0.3 / 0.003);
  // The floor is 10× the reference's own change of F (2e-9).
  EXPECT_DOUBLE_EQ(v.convergence_floor, 2e-8);
  calc_first_screen(v);
  ASSERT_EQ(v.verdicts.size(), 3u);
  EXPECT_TRUE(v.verdicts[1].decides);  // F has a threshold
  ASSERT_TRUE(v.budget);
  EXPECT_DOUBLE_EQ(v.budget->reference, 2e-9);
  EXPECT_EQ(v.baselines.front().what, "reference");
}

}  // namespace
}  // namespace rdyn::validate
