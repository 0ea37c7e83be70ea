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

double norm2(Vec2 v) { return std::hypot(v.x, v.y); }

// The generated leg against de Leva (1996), Table 4, males: the bicycle's subject is de Leva's
// reference male (1.741 m, 73.0 kg), so segment lengths come out as the table's millimetres.
TEST(BicycleLeg, SegmentsFollowDeLevaTable4) {
  const Scene s = load_scene("bicycle");
  const Body& thigh = *s.find_body("thigh_r");
  const Body& shank = *s.find_body("shank_r");  // shank + foot, ankle locked
  const double L_t = thigh.points.at("knee").x;
  EXPECT_NEAR(L_t, 0.4222, 1e-12);                             // thigh 422.2 mm (hip → knee centre)
  EXPECT_NEAR(norm2(shank.points.at("ankle")), 0.4340, 1e-12);  // shank 434.0 mm (knee → malleolus)
  EXPECT_NEAR(thigh.com_m.x / L_t, 0.4095, 1e-12);              // thigh CoM 40.95 % from the hip
  EXPECT_NEAR(std::sqrt(thigh.inertia_kgm2 / thigh.mass_kg) / L_t, 0.329, 1e-12);  // r_gyr 32.9 %
  // One leg weighs thigh + shank + foot = 14.16 + 4.33 + 1.37 = 19.86 % of the body.
  EXPECT_NEAR((thigh.mass_kg + shank.mass_kg) / 73.0, 0.1986, 1e-12);
  EXPECT_EQ(s.find_body("thigh_l")->mass_kg, thigh.mass_kg);  // both legs alike
  // The locked foot adds its own inertia and a parallel-axis term: the composite's inertia
  // exceeds the two segments' centroidal ones (shank r_gyr 25.5 % of 434 mm, foot 25.7 % of
  // 258.1 mm heel–toe).
  const double own = 0.0433 * 73.0 * std::pow(0.255 * 0.434, 2) + 0.0137 * 73.0 * std::pow(0.257 * 0.2581, 2);
  EXPECT_GT(shank.inertia_kgm2, own * 1.01);
}

// Scaling: segment lengths follow stature and masses follow body mass, each alone.
TEST(BicycleLeg, SegmentsScaleWithStatureAndMass) {
  const Scene ref = load_scene("bicycle");
  const Scene big = load_scene("bicycle", {parse_override("bicycle_leg.subject.height_m=1.85"),
                                           parse_override("bicycle_leg.subject.mass_kg=90")});
  const double kh = 1.85 / 1.741, km = 90.0 / 73.0;
  const Body &t0 = *ref.find_body("thigh_r"), &t1 = *big.find_body("thigh_r");
  EXPECT_NEAR(t1.points.at("knee").x, kh * t0.points.at("knee").x, 1e-12);
  EXPECT_NEAR(t1.mass_kg, km * t0.mass_kg, 1e-12);
  EXPECT_NEAR(t1.inertia_kgm2, km * kh * kh * t0.inertia_kgm2, 1e-12);  // m (ρ L)²
  EXPECT_NEAR(norm2(big.find_body("shank_r")->points.at("ankle")),
              kh * norm2(ref.find_body("shank_r")->points.at("ankle")), 1e-12);
  EXPECT_NEAR(big.find_body("shank_r")->mass_kg, km * ref.find_body("shank_r")->mass_kg, 1e-12);
}

// The leg closes at the pedal over the whole crank circle: the hip–pedal distance stays
// between the leg's shortest and longest reach, and at the farthest pedal position (on the
// hip–bottom-bracket line) the knee is flexed by the requested 30°.
TEST(BicycleLeg, TheLegReachesThePedalAllRoundAndExtendsTo30Degrees) {
  const Scene s = load_scene("bicycle");
  const Vec2 H = s.ground_points.at("hip"), B = s.ground_points.at("bottom_bracket");
  const double L_t = s.find_body("thigh_r")->points.at("knee").x;
  const Vec2 p = s.find_body("shank_r")->points.at("pedal");  // in the shank frame (knee at 0)
  const double L_kp = norm2(p), D = norm2({H.x - B.x, H.y - B.y}), Lc = 0.170;
  EXPECT_LE(D + Lc, L_t + L_kp);                 // reaches the farthest pedal position
  EXPECT_GE(D - Lc, std::abs(L_t - L_kp));       // folds enough for the nearest
  // Full extension: thigh along x, shank turned by the flexion φ; the pedal at distance D + Lc.
  auto reach = [&](double phi) {
    return norm2({L_t + std::cos(phi) * p.x - std::sin(phi) * p.y, std::sin(phi) * p.x + std::cos(phi) * p.y});
  };
  const double phi = 30 * kPi / 180;
  EXPECT_NEAR(std::min(std::abs(reach(phi) - (D + Lc)), std::abs(reach(-phi) - (D + Lc))), 0.0, 1e-9);
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

// Road-equivalent flywheel: ½ I ω² must hold the kinetic energy of rider and bike moving at
// v = ω r plus the two wheels spinning at ω. Checked by its derivatives, from generated
// scenes: dI/d(bike mass) = r², dI/d(wheel inertia) = 2 (two wheels), and the rider's share
// m r² when bike and wheels are (nearly) weightless.
TEST(BicycleLeg, RoadEquivalentFlywheelHoldsTheRoadKineticEnergy) {
  auto inertia = [](double bike_kg, double wheel_kgm2, double radius_m) {
    BicycleLegParams p;
    p.bike_mass_kg = bike_kg, p.wheel_inertia_kgm2 = wheel_kgm2, p.wheel_radius_m = radius_m;
    Scene s;
    make_bicycle_leg(p, s);
    return s.find_body("flywheel")->inertia_kgm2;
  };
  const double r = 0.335;
  EXPECT_NEAR(inertia(19.0, 0.09, r) - inertia(9.0, 0.09, r), 10.0 * r * r, 1e-12);
  EXPECT_NEAR(inertia(9.0, 0.29, r) - inertia(9.0, 0.09, r), 2 * 0.2, 1e-12);
  EXPECT_NEAR(inertia(1e-9, 1e-12, r), 73.0 * r * r, 1e-6);
  // Energy at 5 rad/s of the wheel: ½ I ω² = ½ (m + m_bike) (ω r)² + 2 · ½ I_w ω².
  const double w = 5.0;
  EXPECT_NEAR(0.5 * inertia(9.0, 0.09, r) * w * w, 0.5 * 82.0 * std::pow(w * r, 2) + 0.09 * w * w, 1e-9);
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
