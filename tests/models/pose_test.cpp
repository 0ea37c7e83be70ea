// models::calc_pose against closed forms: a two-link revolute arm and a slider, written out by
// hand from the joint definitions (models/scene.hpp, Joint).
#include "models/pose.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace rdyn::models {
namespace {

Scene arm() {
  Scene s;
  s.bodies = {Body{"a", 1, {}, 1, {}}, Body{"b", 1, {}, 1, {{"tip", Vec2{0.3, 0.1}}}}};
  Joint ja;
  ja.name = "ja", ja.parent = kGround, ja.child = "a", ja.parent_point = {1.0, 2.0}, ja.child_point = {0, 0};
  ja.offset_rad = 0.1;
  Joint jb;
  jb.name = "jb", jb.parent = "a", jb.child = "b", jb.parent_point = {0.5, 0.0}, jb.child_point = {-0.2, 0.0};
  s.joints = {jb, ja};  // child listed first: the order of the scene must not matter
  return s;
}

TEST(Pose, TwoLinkArmMatchesTheClosedForm) {
  const Scene s = arm();
  const Pose p = calc_pose(s, {-0.7, 0.3});  // jb, ja (scene order)
  const double th_a = 0.1 + 0.3, th_b = th_a - 0.7;
  EXPECT_NEAR(p.bodies[0].angle_rad, th_a, 1e-15);
  EXPECT_NEAR(p.bodies[0].x_m, 1.0, 1e-15);
  EXPECT_NEAR(p.bodies[0].y_m, 2.0, 1e-15);
  const double jx = 1.0 + 0.5 * std::cos(th_a), jy = 2.0 + 0.5 * std::sin(th_a);
  EXPECT_NEAR(p.joints[0].x, jx, 1e-15);
  EXPECT_NEAR(p.joints[0].y, jy, 1e-15);
  EXPECT_NEAR(p.joints[1].x, 1.0, 1e-15);
  EXPECT_NEAR(p.bodies[1].angle_rad, th_b, 1e-15);
  EXPECT_NEAR(p.bodies[1].x_m, jx + 0.2 * std::cos(th_b), 1e-15);
  EXPECT_NEAR(p.bodies[1].y_m, jy + 0.2 * std::sin(th_b), 1e-15);
  // The tip, 0.5 m along b from the joint and 0.1 m across it.
  const Vec2 tip = calc_ground_point(s, p, "b", {0.3, 0.1});
  EXPECT_NEAR(tip.x, jx + 0.5 * std::cos(th_b) - 0.1 * std::sin(th_b), 1e-15);
  EXPECT_NEAR(tip.y, jy + 0.5 * std::sin(th_b) + 0.1 * std::cos(th_b), 1e-15);
  const Vec2 g = calc_ground_point(s, p, kGround, {4, 5});
  EXPECT_EQ(g.x, 4);
  EXPECT_EQ(g.y, 5);
}

TEST(Pose, SliderMovesAlongItsAxisWithoutTurning) {
  Scene s;
  s.bodies = {Body{"c", 1, {}, 1, {}}};
  Joint j;
  j.name = "slide", j.type = JointType::Prismatic, j.parent = kGround, j.child = "c";
  j.parent_point = {1, 1}, j.child_point = {0.1, 0}, j.axis = {0.6, 0.8};
  s.joints = {j};
  const Pose p = calc_pose(s, {2.0});
  EXPECT_NEAR(p.joints[0].x, 1 + 1.2, 1e-15);
  EXPECT_NEAR(p.joints[0].y, 1 + 1.6, 1e-15);
  EXPECT_EQ(p.bodies[0].angle_rad, 0.0);
  EXPECT_NEAR(p.bodies[0].x_m, 2.2 - 0.1, 1e-15);
}

TEST(Pose, RefusesWrongSizesNonFiniteValuesAndBrokenTrees) {
  const Scene s = arm();
  EXPECT_THROW(calc_pose(s, {0.1}), std::invalid_argument);
  EXPECT_THROW(calc_pose(s, {0.1, std::numeric_limits<double>::quiet_NaN()}), std::invalid_argument);
  Scene loop = s;
  loop.joints[1].parent = "b";  // a → b → a: no root at ground
  EXPECT_THROW(calc_pose(loop, {0.1, 0.2}), std::invalid_argument);
  Scene unknown = s;
  unknown.joints[0].child = "nobody";
  EXPECT_THROW(calc_pose(unknown, {0.1, 0.2}), std::invalid_argument);
  EXPECT_THROW(calc_ground_point(s, calc_pose(s, {0, 0}), "nobody", {}), std::invalid_argument);
}

}  // namespace
}  // namespace rdyn::models
