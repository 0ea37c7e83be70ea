// calibrate_on_table (validate/analysis/calibrate_on_table.cpp): the table lent to the reduced
// model gives the copying route's calibration bit for bit and comes back unchanged, also when the
// calibration fails; only a model that cannot be built leaves it empty.
#include "validate/analysis/calibrate_on_table.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "models/scene_yaml.hpp"
#include "reduced/table.hpp"
#include "tests/validate/analysis/same_calibration.hpp"

namespace rdyn::validate {
namespace {

// A 50 kg·m² wheel against a viscous brake of 1e4 N·m·s: holding 20 Hz needs c·ω ≈ 1.26e6 N·m,
// beyond the scene limit (1e6), 2 Hz ≈ 1.26e5 N·m does not.
models::Scene heavy_flywheel() {
  return models::parse_scene(
      "name: flywheel\n"
      "bodies: [{name: wheel, mass_kg: 2.0, inertia_kgm2: 50.0}]\n"
      "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]\n"
      "independent: wheel\n"
      "loads:\n"
      "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 1.0e4}\n"
      "  - {type: joint_torque, name: drive, joint: wheel, torque_Nm: 0.3}\n"
      "initial: {q_deg: 0, qdot: 5.0}\n"
      "simulation: {duration_s: 2, output_interval_s: 0.01, tolerance: 1.0e-9}\n",
      "flywheel.yaml");
}

TEST(CalibrateOnTable, AgreesWithTheCopyingRouteAndGivesTheTableBack) {
  const auto scene = models::load_scene("bicycle", {{"bicycle_leg.subject.height_m", "1.75"}});
  CalibrationOptions opt = calibration_options_of(scene, 0.0, 0.0, "");
  opt.full_max_s = 0.0;
  CalibrationTable table = extract_calibration_table(scene, opt);
  const std::vector<double> coef = table.table.coef;
  Progress quiet(false);
  const auto copied = calibrate(scene, table, opt, quiet);  // builds its model on a copy
  const auto lent = calibrate_on_table(table, scene, scene, opt, quiet);
  test::expect_same_calibration(copied, lent);
  // The scene's 125 W dissipated on the steady cycle (the power search's tolerance: 1e-8 in log).
  EXPECT_NEAR(lent.mean_dissipated_power_w, 125.0, 125.0 * 2e-8);
  EXPECT_EQ(table.table.coef, coef);            // back, unchanged
  // Lent twice more: the same answer (the model's loads changed, never the table).
  EXPECT_EQ(calibrate_on_table(table, scene, scene, opt, quiet).load_value, copied.load_value);
}

TEST(CalibrateOnTable, AFailedCalibrationStillGivesTheTableBack) {
  const auto scene = heavy_flywheel();
  CalibrationOptions opt = calibration_options_of(scene, 20.0, 0.0, "drive");
  opt.full_max_s = 0.0;
  CalibrationTable table = extract_calibration_table(scene, opt);
  const std::vector<double> coef = table.table.coef;
  ASSERT_FALSE(coef.empty());
  Progress quiet(false);
  EXPECT_THROW(calibrate_on_table(table, scene, scene, opt, quiet), models::NumericalError);
  EXPECT_EQ(table.table.coef, coef);
  opt.cadence_hz = 2.0;  // within the limit: T = c·ω on the table given back
  EXPECT_NEAR(calibrate_on_table(table, scene, scene, opt, quiet).load_value, 1e4 * 2 * M_PI * 2.0,
              1e-6 * 1e4 * 2 * M_PI * 2.0);
}

TEST(CalibrateOnTable, AModelThatCannotBeBuiltLeavesTheTableEmpty) {
  const auto scene = heavy_flywheel();
  CalibrationOptions opt = calibration_options_of(scene, 2.0, 0.0, "drive");
  opt.full_max_s = 0.0;
  CalibrationTable table = extract_calibration_table(scene, opt);
  auto other = scene;
  other.bodies[0].inertia_kgm2 = 40.0;  // another mechanism: its samples do not fit
  Progress quiet(false);
  EXPECT_THROW(calibrate_on_table(table, other, other, opt, quiet), std::exception);
  EXPECT_TRUE(table.table.coef.empty());
}

}  // namespace
}  // namespace rdyn::validate
