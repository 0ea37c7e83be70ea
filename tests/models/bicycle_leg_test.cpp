// Bicycle-leg generator: anthropometry, bike fit and loads as specified.
#include "models/bicycle_leg.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "models/anthropometry.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::models {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(BicycleLeg, SegmentMassesFollowDeLeva) {
  const Scene s = load_scene("bicycle");
  const auto f = de_leva_1996("male");
  EXPECT_NEAR(s.find_body("thigh_r")->mass_kg, 0.1416 * 73.0, 1e-12);
  EXPECT_NEAR(s.find_body("shank_r")->mass_kg, (0.0433 + 0.0137) * 73.0, 1e-12);
  // Thigh length 422.2 mm of 1741 mm stature; the knee sits at its end.
  EXPECT_NEAR(s.find_body("thigh_r")->points.at("knee").x, f.thigh.length * 1.741, 1e-12);
  EXPECT_NEAR(s.find_body("shank_r")->points.at("ankle").x, 0.434, 1e-12);
}

TEST(BicycleLeg, SaddleHeightGivesRequestedKneeFlexionAtExtension) {
  BicycleLegParams p;
  Scene s;
  make_bicycle_leg(p, s);
  double min_flexion = 1e9, max_flexion = 0;
  for (int deg = 0; deg < 360; ++deg) {
    const double f = bicycle_knee_flexion(p, s, deg * kPi / 180.0);
    min_flexion = std::min(min_flexion, f);
    max_flexion = std::max(max_flexion, f);
  }
  // The most extended pose lies on the hip–bottom-bracket line; sampling at 1° can only
  // miss the minimum by a little.
  EXPECT_NEAR(min_flexion * 180.0 / kPi, 30.0, 0.2);
  EXPECT_GT(max_flexion * 180.0 / kPi, 90.0);
  EXPECT_LT(max_flexion * 180.0 / kPi, 130.0);
}

TEST(BicycleLeg, OneLegHasOneLoopAndOneTorque) {
  BicycleLegParams p;
  p.legs = 1;
  Scene s;
  s.independent = "crank";
  make_bicycle_leg(p, s);
  EXPECT_EQ(s.loops.size(), 1u);
  EXPECT_EQ(s.joint_torques.size(), 1u);
  // joints: crank, flywheel, hip, knee; loops remove 2, gear 1 → one degree of freedom.
  EXPECT_EQ(static_cast<int>(s.joints.size()) - 2 * 1 - 1, 1);
}

TEST(BicycleLeg, RoadEquivalentFlywheel) {
  BicycleLegParams p;
  Scene s;
  make_bicycle_leg(p, s);
  // (m_rider + m_bike) r² + 2 I_wheel
  EXPECT_NEAR(s.find_body("flywheel")->inertia_kgm2, (73.0 + 9.0) * 0.335 * 0.335 + 2 * 0.09,
              1e-12);
}

// The field make_bicycle_leg refuses after `edit`, and its message; empty when it builds.
std::pair<std::string, std::string> refusal(void (*edit)(BicycleLegParams&)) {
  BicycleLegParams p;
  edit(p);
  Scene s;
  try {
    make_bicycle_leg(p, s);
  } catch (const SceneError& e) {
    return {e.field(), e.what()};
  }
  return {};
}

TEST(BicycleLeg, NegativeZeroOrOutlandishInputsAreRefusedNotReplaced) {
  struct Case {
    void (*edit)(BicycleLegParams&);
    const char* field;
    const char* range;
  };
  const Case cases[] = {
      {[](BicycleLegParams& p) { p.height_m = -1.7; }, "bicycle_leg.subject.height_m",
       "[0.5, 2.6] m"},
      {[](BicycleLegParams& p) { p.mass_kg = 0; }, "bicycle_leg.subject.mass_kg", "[10, 400] kg"},
      {[](BicycleLegParams& p) { p.crank_length_m = -0.17; }, "bicycle_leg.crank_length_m",
       "[0.05, 0.4] m"},
      {[](BicycleLegParams& p) { p.crank_mass_kg = 0; }, "bicycle_leg.crank_mass_kg", "(0, 20] kg"},
      {[](BicycleLegParams& p) { p.seat_tube_angle_deg = -73; }, "bicycle_leg.seat_tube_angle_deg",
       "[45, 90]"},
      {[](BicycleLegParams& p) { p.knee_flexion_at_extension_deg = 0; },
       "bicycle_leg.knee_flexion_at_extension_deg", "(0, 90]"},
      {[](BicycleLegParams& p) { p.ankle_angle_deg = -100; }, "bicycle_leg.ankle_angle_deg",
       "[70, 140]"},
      {[](BicycleLegParams& p) { p.pedal_stack_m = -0.02; }, "bicycle_leg.pedal_stack_m",
       "[0, 0.1] m"},
      {[](BicycleLegParams& p) { p.hip_torque_Nm = -69.7; }, "bicycle_leg.hip_torque_Nm",
       "[0, 1000]"},
      {[](BicycleLegParams& p) { p.hip_torque_Nm = NAN; }, "bicycle_leg.hip_torque_Nm",
       "[0, 1000]"},
      {[](BicycleLegParams& p) { p.gear_ratio = 0; }, "bicycle_leg.flywheel.gear_ratio",
       "[0.1, 20]"},
      // Before, an inertia ≤ 0 silently became the road equivalent.
      {[](BicycleLegParams& p) { p.flywheel_inertia_kgm2 = 0.0; },
       "bicycle_leg.flywheel.inertia_kgm2", "(0, 1000]"},
      {[](BicycleLegParams& p) { p.flywheel_inertia_kgm2 = -5.0; },
       "bicycle_leg.flywheel.inertia_kgm2", "(0, 1000]"},
      {[](BicycleLegParams& p) { p.flywheel_mass_kg = -10; }, "bicycle_leg.flywheel.mass_kg",
       "(0, 1000] kg"},
      {[](BicycleLegParams& p) { p.bike_mass_kg = 0; }, "bicycle_leg.flywheel.bike_mass_kg",
       "(0, 100] kg"},
      {[](BicycleLegParams& p) { p.wheel_radius_m = INFINITY; },
       "bicycle_leg.flywheel.wheel_radius_m", "[0.1, 0.5] m"},
      {[](BicycleLegParams& p) { p.wheel_inertia_kgm2 = -0.09; },
       "bicycle_leg.flywheel.wheel_inertia_kgm2", "(0, 1]"},
      {[](BicycleLegParams& p) { p.resistance_power_W = -125; }, "bicycle_leg.resistance.power_W",
       "[0, 100000] W"},
      {[](BicycleLegParams& p) { p.resistance_cadence_Hz = 0; },
       "bicycle_leg.resistance.cadence_Hz", "(0, 20] Hz"},
      {[](BicycleLegParams& p) { p.legs = 3; }, "bicycle_leg.legs", "1 or 2"},
  };
  for (const auto& c : cases) {
    const auto [field, message] = refusal(c.edit);
    EXPECT_EQ(field, c.field) << message;
    EXPECT_NE(message.find(c.range), std::string::npos) << message;
  }
  // Zero where zero means "none of it" is allowed: no drive torque, no brake, no pedal stack.
  EXPECT_EQ(refusal([](BicycleLegParams& p) {
              p.hip_torque_Nm = 0, p.resistance_power_W = 0, p.pedal_stack_m = 0;
            }).first,
            "");
}

TEST(BicycleLeg, GeneratorErrorsInAFileNameTheLine) {
  const std::string y =
      "name: b\nbicycle_leg:\n  subject: {height_m: 1.8}\n  flywheel:\n    gear_ratio: -3\n";
  try {
    parse_scene(y, "b.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_EQ(e.field(), "bicycle_leg.flywheel.gear_ratio");
    EXPECT_EQ(e.line(), 5);
  }
  // Omitting the inertia keeps the road equivalent; giving one uses it.
  const Scene road = parse_scene("name: b\nbicycle_leg: {flywheel: {gear_ratio: 3}}\n", "b.yaml");
  EXPECT_NEAR(road.find_body("flywheel")->inertia_kgm2, (73.0 + 9.0) * 0.335 * 0.335 + 2 * 0.09,
              1e-12);
  const Scene given =
      parse_scene("name: b\nbicycle_leg: {flywheel: {inertia_kgm2: 2.5}}\n", "b.yaml");
  EXPECT_DOUBLE_EQ(given.find_body("flywheel")->inertia_kgm2, 2.5);
}

TEST(BicycleLeg, ImpossibleFitIsRefused) {
  BicycleLegParams p;
  p.knee_flexion_at_extension_deg = 0.001;
  Scene s;
  EXPECT_THROW(make_bicycle_leg(p, s), SceneError);
}

}  // namespace
}  // namespace rdyn::models
