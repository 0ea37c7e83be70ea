// Branch guard of forward dynamics: the guard's continuation keeps the starting branch through
// singular configurations (closed form of the parallelogram), and the comparison flags a joint
// off that branch by more than its tolerance, not a turn relabelled or a projection's error.
#include "engine/branch_guard.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "engine/forward_dynamics.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"
#include "test_scenes.hpp"

namespace rdyn::engine {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The parallelogram's own branch (test_scenes.hpp): rocker = crank, coupler = −crank.
std::vector<double> parallelogram_branch(double crank) { return {crank, -crank, crank}; }

TEST(FollowBranch, KeepsTheParallelogramThroughItsAlignedPositions) {
  const FullModel model(models::parse_scene(test::parallelogram_yaml(0.0, true), "p.yaml"));
  BranchGuard guard(model);
  // Two turns backwards and one forwards from 40°, through 0° and ±180° (samples of 0.5 rad,
  // moves of at most 0.1 rad): the rocker follows the crank, the coupler translates.
  for (double q = 40 * kPi / 180; q > 40 * kPi / 180 - 4 * kPi; q -= 0.5) {
    const auto c = calc_branch_check(model, guard, q, parallelogram_branch(q));
    EXPECT_TRUE(c.on_branch) << q;
    EXPECT_NEAR(std::remainder(c.expected - c.integrated, 2 * kPi), 0.0, 1e-9) << q;
  }
  // Exactly at an aligned position and out the other side.
  for (double q : {-4 * kPi, -4 * kPi + 0.05, -3 * kPi, -2.5 * kPi}) {
    const auto c = calc_branch_check(model, guard, q, parallelogram_branch(q));
    EXPECT_TRUE(c.on_branch) << q;
  }
}

TEST(BranchCheck, FlagsAJointOffTheBranchByMoreThanItsTolerance) {
  const FullModel model(models::parse_scene(test::parallelogram_yaml(0.0, true), "p.yaml"));
  BranchGuard guard(model);
  const double q = 50 * kPi / 180;
  auto joints = parallelogram_branch(q);
  joints[2] += 2 * kPi;  // the same configuration, relabelled by a turn
  joints[1] += 1e-6;     // a projection's error
  EXPECT_TRUE(calc_branch_check(model, guard, q, joints).on_branch);
  joints[2] += 0.01;  // 10 × the tolerance off
  const auto c = calc_branch_check(model, guard, q, joints);
  EXPECT_FALSE(c.on_branch);
  EXPECT_EQ(model.scene().joints[c.joint].name, "rocker");
  EXPECT_NEAR(c.expected, q, 1e-9);
  EXPECT_EQ(c.tolerance, kBranchTolerance_rad);
  const std::string m = describe_branch_switch(model, c, 1.5, 1.49);
  EXPECT_NE(m.find("joint 'rocker' is at 50.573°"), std::string::npos) << m;  // 50° + 0.01 rad, less a turn
  EXPECT_NE(m.find("has it at 50°"), std::string::npos) << m;
  EXPECT_NE(m.find("t = 1.49 s and t = 1.5 s"), std::string::npos) << m;
}

}  // namespace
}  // namespace rdyn::engine
