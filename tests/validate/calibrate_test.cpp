// Calibration: the torque it finds holds the cadence in both models, and obeys the
// energy balance per revolution.
#include "validate/calibrate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <fstream>

#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

TEST(Calibrate, BicycleHoldsTheCadenceAndBalancesEnergy) {
  const auto scene = models::load_scene("bicycle");
  CalibrationOptions opt;
  opt.cadence_hz = 1.0;
  opt.power_w = 125.0;
  opt.full_check_s = 3.0;
  Progress quiet(false);
  const auto r = calibrate(scene, opt, quiet);
  EXPECT_NEAR(r.mean_cadence_hz_reduced, 1.0, 1e-8);
  EXPECT_NEAR(r.mean_cadence_hz_full, 1.0, 1e-3);
  EXPECT_NEAR(r.mean_power_w, 125.0, 0.01);
  // Steady state: hip work per revolution T·Σ Δθ_thigh = 125 J (P / f).
  EXPECT_NEAR(r.torque_Nm * r.drive_work_per_rev_per_Nm, 125.0, 0.01);
  // Two thighs, each descending through a realistic swing (40°–70°).
  EXPECT_GT(r.drive_work_per_rev_per_Nm / 2, 40 * M_PI / 180);
  EXPECT_LT(r.drive_work_per_rev_per_Nm / 2, 70 * M_PI / 180);
}

TEST(Calibrate, WrittenSceneScalesProfiledLoadsWhereTheSceneListsThem) {
  // bicycle-profile: hip_torque_Nm 0 (no generated torques) and two profiled hip torques under
  // `loads`: the amplitudes are rewritten there, the generator's hip torque stays 0 (setting it
  // would add constant hip torques beside the profiles).
  std::ifstream in(std::string(RDYN_SCENES) + "/bicycle-profile.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const auto scene = models::parse_scene(text.str(), "bicycle-profile.yaml");
  CalibrationResult r;
  r.torque_Nm = 12.5;
  r.steady_qdot = 6.0;
  const std::string out = calibrated_scene_yaml("bicycle-profile.yaml", text.str(), {}, scene, CalibrationOptions{}, r);
  const auto again = models::parse_scene(out, "written.yaml");
  ASSERT_EQ(again.joint_torques.size(), 2u);
  for (const auto& t : again.joint_torques) {
    EXPECT_TRUE(t.profile) << t.name;
    EXPECT_EQ(t.value, 12.5) << t.name;
  }
}

TEST(Calibrate, HigherPowerNeedsProportionallyMoreTorque) {
  // Viscous resistance at a fixed cadence: dissipation ∝ P, and the gated hip work per
  // revolution is T·Δθ, so T ∝ P (up to the tiny speed fluctuation).
  const auto scene = models::load_scene("bicycle");
  CalibrationOptions opt;
  opt.full_check_s = 1.5;
  Progress quiet(false);
  opt.power_w = 100;
  const double t100 = calibrate(scene, opt, quiet).torque_Nm;
  opt.power_w = 200;
  const double t200 = calibrate(scene, opt, quiet).torque_Nm;
  EXPECT_NEAR(t200 / t100, 2.0, 2e-3);
}

}  // namespace
}  // namespace rdyn::validate
