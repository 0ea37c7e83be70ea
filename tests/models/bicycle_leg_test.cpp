// Bicycle-leg generator: anthropometry, bike fit and loads as specified.
#include "models/bicycle_leg.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

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
  EXPECT_NEAR(s.find_body("flywheel")->inertia_kgm2, (73.0 + 9.0) * 0.335 * 0.335 + 2 * 0.09, 1e-12);
}

TEST(BicycleLeg, ImpossibleFitIsRefused) {
  BicycleLegParams p;
  p.knee_flexion_at_extension_deg = 0.001;
  Scene s;
  EXPECT_THROW(make_bicycle_leg(p, s), SceneError);
}

}  // namespace
}  // namespace rdyn::models
