// The fold of geared bodies: the bicycle's flywheel folds into the crank with r²·I and the
// offset of its joints' guesses; anything that touches the flywheel keeps it a body (one row per
// condition); in a chain of gears only the leaf folds, into the middle body.
#include "models/gear_fold.hpp"

#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <functional>

#include "models/scene_yaml.hpp"

namespace rdyn::models {
namespace {

Joint& joint(Scene& s, const std::string& name) { return s.joints[s.joint_index(name)]; }

TEST(GearFold, BicycleFlywheelFoldsIntoTheCrankWithRSquaredInertia) {
  Scene s = load_scene("bicycle");
  joint(s, "crank").guess = 0.2;
  joint(s, "flywheel").guess = 0.3;
  ASSERT_EQ(s.gears.size(), 1u);
  const double r = s.gears[0].ratio;
  EXPECT_EQ(r, 3.0);  // bicycle_leg.flywheel.gear_ratio
  const auto folds = calc_gear_folds(s);
  ASSERT_EQ(folds.size(), 1u);
  const GearFold& f = folds[0];
  EXPECT_EQ(f.gear, 0);
  EXPECT_EQ(s.bodies[f.body].name, "flywheel");
  EXPECT_EQ(s.bodies[f.driver_body].name, "crank");
  EXPECT_EQ(s.joints[f.driven_joint].name, "flywheel");
  EXPECT_EQ(s.joints[f.driver_joint].name, "crank");
  EXPECT_EQ(f.ratio, r);
  // ½ I (r u)² = ½ (r² I) u²: 9 times the flywheel's own inertia on the crank.
  EXPECT_NEAR(f.moved_inertia_kgm2, 9.0 * s.find_body("flywheel")->inertia_kgm2, 1e-15);
  // q_flywheel = r·q_crank + c through the guesses: 0.3 = 3·0.2 + c.
  EXPECT_NEAR(f.q_offset, 0.3 - 3.0 * 0.2, 1e-15);
  EXPECT_NEAR(calc_gear_offset(s, s.gears[0]), -0.3, 1e-15);
  EXPECT_EQ(calc_foldable_gears(s), std::vector<bool>{true});
}

// One condition of the fold each: the bicycle with the flywheel touched in one way.
struct Touch {
  const char* what;
  std::function<void(Scene&)> apply;
};

void PrintTo(const Touch& t, std::ostream* os) { *os << t.what; }

class GearFoldRefused : public ::testing::TestWithParam<Touch> {};

TEST_P(GearFoldRefused, FlywheelStaysABody) {
  Scene s = load_scene("bicycle");
  ASSERT_EQ(calc_foldable_gears(s), std::vector<bool>{true});
  GetParam().apply(s);
  EXPECT_FALSE(calc_foldable_gears(s).at(0)) << GetParam().what;
  for (const auto& f : calc_gear_folds(s)) EXPECT_NE(s.bodies[f.body].name, "flywheel") << GetParam().what;
}

INSTANTIATE_TEST_SUITE_P(
    EachCondition, GearFoldRefused,
    ::testing::Values(
        Touch{"motion requested", [](Scene& s) { s.outputs.bodies.push_back("flywheel"); }},
        Touch{"centre of mass off the axis", [](Scene& s) { s.bodies[s.body_index("flywheel")].com_m.x += 1e-6; }},
        Touch{"a spring on it", [](Scene& s) { s.springs.push_back({"k", "ground", {0, 0}, "flywheel", {0.01, 0}, 10, 0}); }},
        Touch{"a point force on it",
              [](Scene& s) { s.point_forces.push_back({"p", "ground", {0, 0}, "flywheel", {0.01, 0}, 1.0, {}, {}}); }},
        Touch{"a point force gated by its joint",
              [](Scene& s) {
                s.point_forces.push_back({"p", "ground", {0, 0.5}, "crank", {0.01, 0}, 1.0, RateGate{"flywheel", 1}, {}});
              }},
        Touch{"a torque on its joint", [](Scene& s) { s.joint_torques.push_back({"t", "flywheel", 1.0, {}, {}}); }},
        Touch{"a torque gated by its joint",
              [](Scene& s) { s.joint_torques.push_back({"t", "crank", 1.0, RateGate{"flywheel", 1}, {}}); }},
        Touch{"a motor on its joint", [](Scene& s) { s.motors.push_back({"m", "flywheel", 1.0, 10.0}); }},
        Touch{"a constraint force at its joint",
              [](Scene& s) { s.outputs.constraint_forces.push_back({"f", "flywheel", {1, 0}}); }},
        Touch{"the independent coordinate", [](Scene& s) { s.independent = "flywheel"; }},
        Touch{"a joint hung from it",
              [](Scene& s) {
                Joint j = s.joints[s.joint_index("flywheel")];
                j.name = "hub", j.parent = "flywheel", j.child = "hub_body";
                s.joints.push_back(j);
              }},
        Touch{"a loop on it",
              [](Scene& s) { s.loops.push_back({"l", "flywheel", {0.01, 0}, "crank", {0.01, 0}, {}}); }},
        Touch{"a second gear on its joint",
              [](Scene& s) { s.gears.push_back({"g2", "crank", "flywheel", 2.0}); }},
        Touch{"its driver not on ground", [](Scene& s) { joint(s, "crank").parent = "thigh_r"; }}),
    [](const ::testing::TestParamInfo<Touch>& info) {
      std::string n;
      for (const char* c = info.param.what; *c; ++c) n += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
      return n;
    });

TEST(GearFold, InAChainOnlyTheLeafFoldsIntoTheMiddleBody) {
  // crank → flywheel (r = 3) → dynamo (r = 2, on ground, turning about its centre of mass): the
  // flywheel drives a gear, so it stays a body; the dynamo folds into it with 2²·I.
  Scene s = load_scene("bicycle");
  Body dynamo = *s.find_body("flywheel");
  dynamo.name = "dynamo";
  dynamo.inertia_kgm2 = 0.01;
  s.bodies.push_back(dynamo);
  Joint j = joint(s, "flywheel");
  j.name = "dynamo", j.child = "dynamo", j.parent_point.x += 0.2;
  s.joints.push_back(j);
  s.gears.push_back({"belt", "flywheel", "dynamo", 2.0});
  EXPECT_EQ(calc_foldable_gears(s), (std::vector<bool>{false, true}));
  const auto folds = calc_gear_folds(s);
  ASSERT_EQ(folds.size(), 1u);
  EXPECT_EQ(folds[0].gear, 1);
  EXPECT_EQ(s.bodies[folds[0].body].name, "dynamo");
  EXPECT_EQ(s.bodies[folds[0].driver_body].name, "flywheel");
  EXPECT_NEAR(folds[0].moved_inertia_kgm2, 4.0 * 0.01, 1e-15);
}

}  // namespace
}  // namespace rdyn::models

namespace rdyn::models {
namespace {

// Turns of the independent coordinate that bring every geared joint back: k·ρ whole for each
// joint's rate ratio ρ (both gear directions, chains multiply).
TEST(GearFold, TurnsToRepeatAreTheLeastCommonWholeTurns) {
  Scene s = load_scene("fourbar");  // crank, coupler, rocker; no gears
  std::string why;
  EXPECT_EQ(calc_turns_to_repeat(s, why), 1);
  s.gears = {{"g", "crank", "rocker", 0.5}};
  EXPECT_EQ(calc_turns_to_repeat(s, why), 2);
  EXPECT_NE(why.find("gear 'g' turns 'rocker' 0.5 turn(s) per turn of 'crank'"), std::string::npos) << why;
  s.gears = {{"g", "crank", "rocker", 3.0}};  // a flywheel geared up: back every turn
  EXPECT_EQ(calc_turns_to_repeat(s, why), 1);
  s.gears = {{"g", "rocker", "crank", 1.5}};  // driven is the independent: ρ_rocker = 1/1.5 = 2/3
  EXPECT_EQ(calc_turns_to_repeat(s, why), 3);
  s.gears = {{"g", "crank", "rocker", 0.5}, {"h", "rocker", "coupler", 0.5}};  // ρ = 1/2, 1/4
  EXPECT_EQ(calc_turns_to_repeat(s, why), 4);
  s.gears = {{"g", "crank", "rocker", 0.5}, {"h", "crank", "coupler", 1.0 / 3}};  // lcm(2, 3)
  EXPECT_EQ(calc_turns_to_repeat(s, why), 6);
  s.gears = {{"g", "crank", "rocker", std::sqrt(2.0)}};
  EXPECT_EQ(calc_turns_to_repeat(s, why), 0);
  EXPECT_NE(why.find("no whole number of turns"), std::string::npos) << why;
}

}  // namespace
}  // namespace rdyn::models
