// The validity domain of the independent coordinate: dead points located on the full model
// against their closed forms; periodic and declared cases.
#include "engine/independent_range.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "models/scene_yaml.hpp"

namespace rdyn::engine {
namespace {

constexpr double kDeg = M_PI / 180;

TEST(IndependentRange, SliderDeadPointsAreRodMinusAndPlusCrank) {
  // In-line slider-crank (crank r = 0.05 m, rod l = 0.20 m) driven from its slider: the loops
  // close only for l − r ≤ s ≤ l + r.
  const FullModel model(models::load_scene("slider-crank-slider"));
  const auto d = calc_independent_domain(model);
  ASSERT_FALSE(d.periodic);
  EXPECT_FALSE(d.revolute);
  ASSERT_TRUE(d.dead_min && d.dead_max);
  EXPECT_NEAR(*d.dead_min, 0.15, 1e-8);
  EXPECT_NEAR(*d.dead_max, 0.25, 1e-8);
  // The domain stops kDeadPointMargin of the stroke short of each.
  EXPECT_NEAR(d.min, 0.15 + kDeadPointMargin * 0.10, 1e-8);
  EXPECT_NEAR(d.max, 0.25 - kDeadPointMargin * 0.10, 1e-8);
  EXPECT_EQ(d.min_edge, "dead point");
  EXPECT_EQ(d.max_edge, "dead point");
  // The documented margin: 1 % of the 0.1 m stroke, 1 mm from each closed-form dead point (a
  // rehabilitation press loses no more than that of its stroke), and the sentence inspect prints.
  EXPECT_NEAR(calc_dead_point_margin(d), 0.001, 1e-10);
  EXPECT_LT(0.25 - d.max, 0.001 + 1e-8);
  EXPECT_GT(0.25 - d.max, 0.001 - 1e-8);
  const std::string why = describe_domain(d, "slider");
  EXPECT_EQ(why.rfind("dead points found at 0.149999999 m and 0.250000001 m", 0), 0u) << why;
  EXPECT_NE(why.find("stops 0.001 m (1 % of their distance) short of each: [0.150999999, 0.249000001] m"),
            std::string::npos)
      << why;
}

TEST(IndependentRange, RockerDeadPointsAreWhereCrankAndCouplerAlign) {
  // Four-bar a = 0.08 (crank), b = 0.28 (coupler), c = 0.20 (rocker), d = 0.30 (ground):
  // |AC|² = d² + c² + 2dc cos ψ with |AC| = b ± a at the rocker's dead points.
  const FullModel model(models::load_scene("fourbar-rocker"));
  const auto d = calc_independent_domain(model);
  ASSERT_FALSE(d.periodic);
  ASSERT_TRUE(d.dead_min && d.dead_max);
  const double a = 0.08, b = 0.28, c = 0.20, g = 0.30;
  auto psi = [&](double AC) { return std::acos((AC * AC - g * g - c * c) / (2 * g * c)); };
  EXPECT_NEAR(*d.dead_min, psi(b + a), 1e-8);
  EXPECT_NEAR(*d.dead_max, psi(b - a), 1e-8);
  EXPECT_NEAR(*d.dead_min / kDeg, 90.19, 0.01);
}

TEST(IndependentRange, ACrankThatTurnsFullyIsPeriodic) {
  const FullModel model(models::load_scene("fourbar"));
  EXPECT_TRUE(calc_independent_domain(model).periodic);
}

TEST(IndependentRange, ADeclaredRangeIsTakenAsGiven) {
  auto scene = models::load_scene("slider-crank-slider");
  scene.independent_range = models::IndependentRange{0.17, 0.23};
  const FullModel model(scene);
  const auto d = calc_independent_domain(model);
  EXPECT_FALSE(d.periodic);
  EXPECT_EQ(d.min, 0.17);
  EXPECT_EQ(d.max, 0.23);
  EXPECT_EQ(d.min_edge, "declared limit");
  EXPECT_FALSE(d.dead_min);
  EXPECT_EQ(calc_dead_point_margin(d), 0.0);  // no margin taken from a declared limit
  EXPECT_EQ(describe_domain(d, "slider"), "declared by the scene: independent_range [0.17, 0.23] m");
}

TEST(IndependentRange, ADeclaredRangeAcrossADeadPointIsRefused) {
  auto scene = models::load_scene("slider-crank-slider");
  scene.independent_range = models::IndependentRange{0.10, 0.24};  // the loops close only from 0.15
  const FullModel model(scene);
  try {
    calc_independent_domain(model);
    FAIL() << "accepted";
  } catch (const EngineError& e) {
    EXPECT_NE(std::string(e.what()).find("crosses a dead point at 0.14999"), std::string::npos) << e.what();
  }
}

TEST(IndependentRange, APrismaticJointWithoutDeadPointsIsUnbounded) {
  // A free slider: nothing stops it, so no range can be found; the full model may still run it.
  const auto scene = models::parse_scene(R"(
name: free
ground_points: {O: [0, 0]}
bodies:
  - {name: slider, mass_kg: 1.0, inertia_kgm2: 1.0e-3, points: {P: [0.2, 0]}}
joints:
  - {name: slide, type: prismatic, parent: ground, parent_point: O, child: slider, axis: [1, 0]}
independent: slide
initial: {q: 0.1}
)",
                                         "free.yaml");
  const FullModel model(scene);
  const auto d = calc_independent_domain(model);
  EXPECT_FALSE(d.periodic);
  EXPECT_EQ(d.min, -INFINITY);
  EXPECT_EQ(d.max, INFINITY);
  EXPECT_NE(d.unbounded_reason.find("no dead point within 8 m"), std::string::npos) << d.unbounded_reason;
}

TEST(IndependentRange, AnInitialPositionNextToADeadPointIsRefused) {
  auto scene = models::load_scene("slider-crank-slider");
  scene.initial.q = 0.1505;  // inside the loops' range, within the 1 % margin (0.001 m) of the dead point
  const FullModel model(scene);
  try {
    calc_independent_domain(model);
    FAIL() << "accepted";
  } catch (const EngineError& e) {
    EXPECT_NE(std::string(e.what()).find("dead point"), std::string::npos) << e.what();
    // The refusal names where the scene gives the initial position.
    EXPECT_NE(std::string(e.what()).find(fmt::format("slider-crank-slider.yaml:{}: field 'initial'",
                                                     scene.line_of("initial"))),
              std::string::npos)
        << e.what();
    EXPECT_GT(scene.line_of("initial"), 0);
  }
}

}  // namespace
}  // namespace rdyn::engine

namespace rdyn::engine {
namespace {

// The walk alone (calibration's check for a full turn): the rocker's dead points at their closed
// form as above, and the parallelogram turns fully with its aligned positions left unscanned,
// where the whole domain finds them.
TEST(IndependentRange, TheWalkAloneFindsEdgesWithoutScanningForSingularPoints) {
  const FullModel rocker(models::load_scene("fourbar-rocker"));
  const auto r = calc_independent_domain_edges(rocker);
  ASSERT_FALSE(r.periodic);
  ASSERT_TRUE(r.dead_min && r.dead_max);
  const double a = 0.08, b = 0.28, c = 0.20, g = 0.30;
  auto psi = [&](double AC) { return std::acos((AC * AC - g * g - c * c) / (2 * g * c)); };
  EXPECT_NEAR(*r.dead_min, psi(b + a), 1e-8);
  EXPECT_NEAR(*r.dead_max, psi(b - a), 1e-8);
  const FullModel parallelogram(models::load_scene(std::string(RDYN_SCENES) + "/hard/parallelogram.yaml"));
  const auto walk = calc_independent_domain_edges(parallelogram);
  EXPECT_TRUE(walk.periodic);
  EXPECT_TRUE(walk.singular.empty());
  const auto whole = calc_independent_domain(parallelogram);
  EXPECT_TRUE(whole.periodic);
  EXPECT_FALSE(whole.singular.empty());
}

}  // namespace
}  // namespace rdyn::engine
