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

// The points a body carries, written out from the arm: a's named point, its joint to ground (its
// origin) and its joint to b; b's child point and named point; ground's pivot. A point given twice
// (a named point on a joint's point) is one.
TEST(Pose, BodyPointsAreTheNamedPointsAndEveryAttachmentOnce) {
  Scene s = arm();
  s.bodies[0].points = {{"mid", Vec2{0.25, 0.0}}, {"at_jb", Vec2{0.5, 0.0}}};
  Loop l;
  l.name = "L", l.body_a = "b", l.point_a = {0.3, 0.1}, l.body_b = kGround, l.point_b = {3, 4};
  s.loops = {l};
  const auto a = calc_body_points(s, "a");
  ASSERT_EQ(a.size(), 3u);  // at_jb, mid (name order), then ja's child point (0, 0); jb's parent point is at_jb
  EXPECT_EQ(a[0].x, 0.5);
  EXPECT_EQ(a[1].x, 0.25);
  EXPECT_EQ(a[2].x, 0.0);
  const auto b = calc_body_points(s, "b");
  ASSERT_EQ(b.size(), 2u);  // tip (also the loop's point), jb's child point
  EXPECT_EQ(b[0].x, 0.3);
  EXPECT_EQ(b[1].x, -0.2);
  const auto g = calc_body_points(s, kGround);
  ASSERT_EQ(g.size(), 2u);  // ja's parent point, the loop's point on ground
  EXPECT_EQ(g[0].x, 1.0);
  EXPECT_EQ(g[1].x, 3.0);
  EXPECT_TRUE(calc_body_points(s, "nobody").empty());
}

// The outline goes round the centroid by angle from −π: a square's corners given in any order
// come back counter-clockwise from the lower left, so the polygon does not cross itself.
TEST(Pose, BodyOutlineGoesRoundTheCentroid) {
  Scene s;
  s.bodies = {Body{"plate", 1, {}, 1, {{"a", Vec2{1, 1}}, {"b", Vec2{-1, -1}}, {"c", Vec2{1, -1}}, {"d", Vec2{-1, 1}}}}};
  Joint j;
  j.name = "pin", j.parent = kGround, j.child = "plate", j.child_point = {1, 1};  // on corner a
  s.joints = {j};
  const auto o = calc_body_outline(s, "plate");
  ASSERT_EQ(o.size(), 4u);
  const double want[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(o[i].x, want[i][0]) << i;
    EXPECT_EQ(o[i].y, want[i][1]) << i;
  }
}

}  // namespace
}  // namespace rdyn::models
