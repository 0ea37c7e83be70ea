// calc_calibrated_run: both models at the operating point a calibration found. Started on the
// reduced steady cycle with the calibrated load, each holds the target cadence over its two
// revolutions (the calibration's own claim, checked here by two independent integrations), and
// they agree with each other to the 10° table's accuracy.
#include "validate/harness/calibrated_run.hpp"

#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/harness/harness.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {
namespace {

TEST(CalibratedRun, BothModelsHoldTheCalibratedCadenceAndAgree) {
  const auto scene = models::load_scene("bicycle");
  CalibrationOptions opt = calibration_options_of(scene, 0.0, 0.0, "");  // 1 Hz, 125 W
  opt.full_max_s = 0;  // the full model's own check is what calc_calibrated_run does here
  Progress quiet(false);
  const auto r = calibrate(scene, opt, quiet);
  const auto table = extract_from_full(extraction_scene(scene), 10, reduced::Method::Kinetostatic).samples;
  const auto c = calc_calibrated_run(scene, opt, r, table, 0.005);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->full.t.size(), c->reduced.t.size());
  EXPECT_NEAR(c->full.t.back(), 2.0, 1e-9);  // two revolutions at 1 Hz
  // Two whole periods of the steady cycle from a point on it: the mean rate is the cadence.
  EXPECT_NEAR(c->mean_cadence_reduced_hz, 1.0, 1e-5);
  EXPECT_NEAR(c->mean_cadence_full_hz, 1.0, 1e-3);
  // The 10° table's accuracy (docs/theory.md: ~1e-5 of the speed, ~2e-3 of the knee force).
  EXPECT_LT(c->qdot_error, 1e-3);
  EXPECT_EQ(c->force_name, "knee");
  EXPECT_LT(c->force_error, 1e-2);
  EXPECT_GT(c->force_error, 0.0);  // two integrations of two models: never identical
  EXPECT_EQ(c->grid_deg, 10.0);
  // A calibration on a 5° grid (validation.calibrate.grid_deg) is shown on its own grid: closer.
  auto opt5 = opt;
  opt5.grid_deg = 5;
  const auto c5 = calc_calibrated_run(scene, opt5, calibrate(scene, opt5, quiet), table, 0.005);
  ASSERT_TRUE(c5);
  EXPECT_EQ(c5->grid_deg, 5.0);
  EXPECT_LT(c5->force_error, c->force_error);
  // An unconfirmed calibration has no operating point to show.
  auto missed = r;
  missed.unconfirmed = "the full model's mean cadence is 0.55 Hz";
  EXPECT_FALSE(calc_calibrated_run(scene, opt, missed, table, 0.005));
}

}  // namespace
}  // namespace rdyn::validate
