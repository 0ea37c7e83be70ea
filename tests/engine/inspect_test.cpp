// Assembly report and domain (engine/inspect.cpp) against closed-form position analysis: the
// four-bar's two assemblies as circle intersections, the rocker's dead points where crank and
// coupler are collinear, the slider-crank's slider position and stroke ends, and the 5 % margin
// the models keep from them.
#include "engine/inspect.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>

#include "models/scene_yaml.hpp"

namespace rdyn::engine {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;

// Four-bar of models/scenes/fourbar.yaml: ground A(0,0)→D(d,0), crank a, coupler b, rocker c.
constexpr double a = 0.08, b = 0.28, c = 0.20, d = 0.30;

std::string fourbar_yaml(const std::string& independent, double q0_deg, double crank_guess, double coupler_guess,
                         double rocker_guess, const std::string& branch = "") {
  return "name: fb\nground_points: {A: [0, 0], D: [0.30, 0]}\nbodies:\n"
         "  - {name: crank, mass_kg: 0.5, com_m: [0.04, 0], inertia_kgm2: 2.667e-4, points: {B: [0.08, 0]}}\n"
         "  - {name: coupler, mass_kg: 1.2, com_m: [0.14, 0], inertia_kgm2: 7.84e-3, points: {C: [0.28, 0]}}\n"
         "  - {name: rocker, mass_kg: 0.9, com_m: [0.10, 0], inertia_kgm2: 3.0e-3, points: {C: [0.20, 0]}}\n"
         "joints:\n"
         "  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank, guess_deg: " +
         std::to_string(crank_guess) +
         "}\n"
         "  - {name: coupler, type: revolute, parent: crank, parent_point: B, child: coupler, guess_deg: " +
         std::to_string(coupler_guess) +
         "}\n"
         "  - {name: rocker, type: revolute, parent: ground, parent_point: D, child: rocker, guess_deg: " +
         std::to_string(rocker_guess) +
         "}\n"
         "loops:\n  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C" +
         (branch.empty() ? "" : ", branch: " + branch) + "}\nindependent: " + independent +
         "\ninitial: {q_deg: " + std::to_string(q0_deg) + ", qdot: 1}\n";
}

// The two positions of C for crank angle θ: intersections of |C − B| = b and |C − D| = c.
// Returns the rocker angles (absolute) of both, the first with C to the left of B→D.
std::pair<double, double> rocker_angles(double th) {
  const double Bx = a * std::cos(th), By = a * std::sin(th);
  const double ex = d - Bx, ey = -By, e = std::hypot(ex, ey);  // B → D
  const double along = (b * b - c * c + e * e) / (2 * e), h = std::sqrt(b * b - along * along);
  const double px = Bx + along * ex / e, py = By + along * ey / e;
  const double C1x = px - h * ey / e, C1y = py + h * ex / e;  // left of B→D
  const double C2x = px + h * ey / e, C2y = py - h * ex / e;
  return {std::atan2(C1y, C1x - d), std::atan2(C2y, C2x - d)};
}

double wrap(double x) { return std::remainder(x, 2 * kPi); }

TEST(Inspect, FourBarAssemblyMatchesTheCircleIntersection) {
  const auto scene = models::parse_scene(fourbar_yaml("crank", 30, 30, 5, 90), "fb.yaml");
  const FullModel model(scene);
  const auto in = calc_inspection(model);
  ASSERT_EQ(in.joints.size(), 3u);
  const double rocker = rocker_angles(30 * kDeg).first;
  EXPECT_NEAR(wrap(in.joints[2].q - rocker), 0.0, 1e-10);
  // Coupler: relative angle = absolute coupler angle (B → C) − crank angle.
  const double Cx = d + c * std::cos(rocker), Cy = c * std::sin(rocker);
  const double coupler_abs = std::atan2(Cy - a * std::sin(30 * kDeg), Cx - a * std::cos(30 * kDeg));
  EXPECT_NEAR(wrap(in.joints[1].q - (coupler_abs - 30 * kDeg)), 0.0, 1e-10);
  EXPECT_NEAR(wrap(in.bodies[1].angle_rad - coupler_abs), 0.0, 1e-10);
  EXPECT_NEAR(in.bodies[2].x_m, d, 1e-12);
  EXPECT_EQ(in.mobility.mobilities - in.mobility.rank, 1);
  EXPECT_EQ(in.mobility.rows, 2);
  ASSERT_EQ(in.loops.size(), 1u);
  EXPECT_LT(in.loops[0].gap_m, 1e-10);
  EXPECT_TRUE(in.range.periodic);  // Grashof crank-rocker: the crank turns fully
  EXPECT_TRUE(in.warnings.empty());
}

TEST(Inspect, RockerRangeEndsAtTheCollinearDeadPoints) {
  // Driven by the rocker, the loops close only between the dead points where crank and coupler
  // are collinear: |AC| = b ± a, |AC|² = d² + c² + 2 d c cos θ. The domain stops
  // kDeadPointMargin of their distance short of each (the models' rule).
  const auto scene = models::parse_scene(fourbar_yaml("rocker", 110, 110, -85, 110), "fb.yaml");
  const auto in = calc_inspection(FullModel(scene));
  const double lo = std::acos(((b + a) * (b + a) - d * d - c * c) / (2 * d * c));
  const double hi = std::acos(((b - a) * (b - a) - d * d - c * c) / (2 * d * c));
  EXPECT_FALSE(in.range.periodic);
  ASSERT_TRUE(in.range.dead_min && in.range.dead_max);
  // The shared walk bisects to 1e-11; the projection it accepts next to a dead point (1e-9 m)
  // leaves ~8e-9 rad.
  EXPECT_NEAR(*in.range.dead_min, lo, 1e-8);
  EXPECT_NEAR(*in.range.dead_max, hi, 1e-8);
  EXPECT_NEAR(in.range.min, lo + kDeadPointMargin * (hi - lo), 2e-8);
  EXPECT_NEAR(in.range.max, hi - kDeadPointMargin * (hi - lo), 2e-8);
  EXPECT_EQ(in.range.min_edge, "dead point");
  EXPECT_EQ(in.range.max_edge, "dead point");
  EXPECT_TRUE(in.warnings.empty());
}

TEST(Inspect, ADeclaredRangeIsReportedAsTheModelsUseIt) {
  auto scene = models::parse_scene(fourbar_yaml("rocker", 110, 110, -85, 110), "fb.yaml");
  scene.independent_range = models::IndependentRange{100 * kDeg, 120 * kDeg};
  const auto in = calc_inspection(FullModel(scene));
  EXPECT_EQ(in.range.min, 100 * kDeg);
  EXPECT_EQ(in.range.max, 120 * kDeg);
  EXPECT_EQ(in.range.min_edge, "declared limit");
  EXPECT_EQ(in.range.max_edge, "declared limit");
  EXPECT_FALSE(in.range.dead_min);
}

TEST(Inspect, AnInitialQInsideTheMarginOfADeadPointIsRefused) {
  // 90.5° lies between the dead point 90.19° and the domain's edge 90.67°: no model may start there.
  const auto scene = models::parse_scene(fourbar_yaml("rocker", 90.5, 90, -60, 90.5), "fb.yaml");
  const FullModel model(scene);
  EXPECT_NO_THROW(calc_assembly(model));  // the assembly itself is fine
  try {
    calc_inspection(model);
    FAIL() << "accepted";
  } catch (const EngineError& e) {
    EXPECT_NE(std::string(e.what()).find("within 1 % of a dead point of 'rocker'"), std::string::npos) << e.what();
  }
}

// A prismatic coordinate without dead points (unbounded, exit 0 with a warning): tests/validate/cli/inspect_test.cpp.

TEST(Inspect, GuessesFarFromTheAssemblyWarn) {
  // Guesses of the other branch's neighbourhood for the coupler: the assembly lands 20°+ away.
  const auto scene = models::parse_scene(fourbar_yaml("crank", 30, 30, 60, 90), "fb.yaml");
  const auto in = calc_assembly(FullModel(scene));
  ASSERT_FALSE(in.warnings.empty());
  EXPECT_NE(in.warnings[0].find("joint 'coupler' assembled at"), std::string::npos) << in.warnings[0];
}

// Slider-crank: crank r = 0.05, rod l = 0.20, slider on the line through the crank axis.
std::string slider_crank_yaml(const std::string& independent, double q0, double crank_guess, double rod_guess,
                              double slider_guess) {
  return "name: sc\nground_points: {O: [0, 0]}\nbodies:\n"
         "  - {name: crank, mass_kg: 0.4, com_m: [0, 0], inertia_kgm2: 2.0e-4, points: {B: [0.05, 0]}}\n"
         "  - {name: rod, mass_kg: 0.6, com_m: [0.08, 0], inertia_kgm2: 2.0e-3, points: {C: [0.20, 0]}}\n"
         "  - {name: slider, mass_kg: 1.5, com_m: [0, 0], inertia_kgm2: 1.0e-3}\n"
         "joints:\n"
         "  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank, guess_deg: " +
         std::to_string(crank_guess) +
         "}\n"
         "  - {name: rod, type: revolute, parent: crank, parent_point: B, child: rod, guess_deg: " +
         std::to_string(rod_guess) +
         "}\n"
         "  - {name: slider, type: prismatic, parent: ground, parent_point: O, child: slider, axis: [1, 0], "
         "guess_m: " +
         std::to_string(slider_guess) +
         "}\n"
         "loops:\n  - {name: pin, body_a: rod, point_a: C, body_b: slider, point_b: [0, 0]}\nindependent: " +
         independent + "\ninitial: {" + (independent == "slider" ? "q: " : "q_deg: ") + std::to_string(q0) +
         ", qdot: 1}\n";
}

TEST(Inspect, SliderCrankPositionAndStroke) {
  const double r = 0.05, l = 0.20, th = 30 * kDeg;
  const auto in = calc_inspection(FullModel(models::parse_scene(slider_crank_yaml("crank", 30, 30, -37, 0.24), "sc")));
  EXPECT_NEAR(in.joints[2].q, r * std::cos(th) + std::sqrt(l * l - r * r * std::sin(th) * std::sin(th)), 1e-12);
  EXPECT_NEAR(wrap(in.joints[1].q + th + std::asin(r * std::sin(th) / l)), 0.0, 1e-10);  // rod angle −asin(r sinθ/l)
  EXPECT_TRUE(in.range.periodic);
  // Driven from the slider: the stroke ends at the dead points x = l ± r (to the 1e-9 m the
  // projection accepts next to them: measured 1.4e-9 m).
  const auto sl = calc_inspection(FullModel(models::parse_scene(slider_crank_yaml("slider", 0.2, 60, -60, 0.2), "sc")));
  EXPECT_FALSE(sl.range.periodic);
  ASSERT_TRUE(sl.range.dead_min && sl.range.dead_max);
  EXPECT_NEAR(*sl.range.dead_min, l - r, 1e-8);
  EXPECT_NEAR(*sl.range.dead_max, l + r, 1e-8);
  EXPECT_NEAR(sl.range.min, l - r + kDeadPointMargin * 2 * r, 2e-8);
  EXPECT_NEAR(sl.range.max, l + r - kDeadPointMargin * 2 * r, 2e-8);
}

TEST(Inspect, BicycleIsOneDegreeOfFreedomAndTurnsFully) {
  const auto scene = models::load_scene("bicycle");
  const auto in = calc_inspection(FullModel(scene));
  EXPECT_EQ(in.mobility.mobilities - in.mobility.rank, 1);
  EXPECT_EQ(in.mobility.rank, in.mobility.rows);
  EXPECT_TRUE(in.range.periodic);
  for (const auto& l : in.loops) EXPECT_LT(l.gap_m, 1e-9) << l.name;
  EXPECT_EQ(in.bodies.size(), scene.bodies.size());
}

}  // namespace
}  // namespace rdyn::engine
