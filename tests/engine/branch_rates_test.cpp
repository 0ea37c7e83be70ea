// Rates along the assembly branch (engine/branch_rates.cpp), through the public calls that use
// them: the kinetostatic sample's velocity ratios r and slopes b = dr/dq against central
// differences of the projected positions (a second route: positions only, no Jacobian solve),
// and the polished rates near a parallelogram's aligned position against its closed form; and
// calc_branch_rates into a BranchRates reused from configuration to configuration (as the
// workspace's) against a fresh one.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/branch_guard.hpp"
#include "engine/branch_rates.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"
#include "test_scenes.hpp"

namespace rdyn::engine {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(BranchRates, RatiosAndSlopesAreTheDerivativesOfTheBranchPositions) {
  // The crank-rocker and the bicycle (four-bars with a geared flywheel): r_j = dp_j/dq and
  // b_j = d²p_j/dq² by central differences of calc_kinetostatic's positions, h = 1e-4 rad
  // (truncation ~h² × p'''' ~ 1e-8, rounding ~1e-12/h² ~ 1e-4 for b: its tolerance).
  for (const char* name : {"fourbar", "bicycle"}) {
    const auto scene = models::load_scene(name);
    const FullModel model(scene);
    FullWorkspace ws(model), probe(model);
    const double h = 1e-4;
    for (double deg = scene.initial.q * 180 / kPi; deg < scene.initial.q * 180 / kPi + 360; deg += 40) {
      const double q = deg * kPi / 180;
      const auto s = calc_kinetostatic_sample(model, ws, q, 0.7, SampleParts::All);
      const auto lo = calc_kinetostatic(model, probe, q - h, 0, 0, Loads::Off);
      const auto mid = calc_kinetostatic(model, probe, q, 0, 0, Loads::Off);
      const auto hi = calc_kinetostatic(model, probe, q + h, 0, 0, Loads::Off);
      for (size_t j = 0; j < scene.joints.size(); ++j) {
        const double d1 = std::remainder(hi.joint_q[j] - lo.joint_q[j], 2 * kPi) / (2 * h);
        const double d2 = (std::remainder(hi.joint_q[j] - mid.joint_q[j], 2 * kPi) -
                           std::remainder(mid.joint_q[j] - lo.joint_q[j], 2 * kPi)) /
                          (h * h);
        EXPECT_NEAR(s.ratio_q[j], d1, 1e-7 * (1 + std::abs(d1))) << name << " " << scene.joints[j].name << " " << deg;
        EXPECT_NEAR(s.ratio_slope[j], d2, 1e-4 * (1 + std::abs(d2))) << name << " " << scene.joints[j].name << " " << deg;
      }
    }
  }
}

TEST(BranchRates, PolishedNearTheAlignedPositionTheyAreTheParallelogramsOwn) {
  // 1e-3…1e-2 rad from the aligned position (conditioning ~3e-4…3e-3: polished to rounding,
  // branch_rates.hpp), the rocker turns with the crank and the coupler against it: r = (1, −1, 1),
  // b = 0, m1 constant. Unpolished, the residual magnified by 1/κ² put r off by ~1e-6 there.
  const FullModel model(models::parse_scene(test::parallelogram_yaml(0.0, true), "p.yaml"));
  BranchGuard branch(model);  // follow the branch from the assembly to each point
  for (double d : {1e-2, 3e-3, 1e-3, -1e-3, -3e-3, -1e-2}) {
    for (double base : {0.0, kPi}) {
      const double q = base + d;
      follow_branch(model, branch.ws, q, branch.max_move, branch.max_correction);
      const auto s = calc_kinetostatic_sample(model, branch.ws, q, 0.0, SampleParts::All);
      EXPECT_NEAR(s.ratio_q[0], 1.0, 1e-12) << q;
      EXPECT_NEAR(s.ratio_q[1], -1.0, 1e-8) << q;
      EXPECT_NEAR(s.ratio_q[2], 1.0, 1e-8) << q;
      for (double b : s.ratio_slope) EXPECT_NEAR(b, 0.0, 1e-6) << q;
      EXPECT_NEAR(s.m1, test::parallelogram_m1(), 1e-9 * test::parallelogram_m1()) << q;
    }
  }
}

TEST(BranchRates, AReusedOneGivesAFreshOnesRatesBitForBit) {
  // calc_branch_rates overwrites every field of its output in place (issue #28: the sample's
  // rates keep their storage in the workspace): at configurations along the turn of mechanisms
  // with loops only, a gear (the bicycle's flywheel), a slider and the crane, the reused
  // BranchRates holds what a fresh one gets, bit for bit, and keeps no stale factorization.
  for (const char* name : {"fourbar", "bicycle", "slider-crank", "crane-luffing", "bicycle-profile"}) {
    const auto scene = models::load_scene(name);
    const FullModel model(scene);
    FullWorkspace ws(model);
    BranchRates reused;
    for (int k = 0; k < 9; ++k) {
      // A turn for a crank; the crane's cylinder over its declared stroke [1.0, 1.9] m.
      const bool revolute = scene.joints[model.impl().independent].type == models::JointType::Revolute;
      const double q = revolute ? scene.initial.q + k * 2 * kPi / 9 : 1.05 + 0.1 * k;
      calc_kinetostatic_sample(model, ws, q, 0.7, SampleParts::All);  // a projected configuration
      SimTK::State& s = ws.impl().state;
      BranchRates fresh;
      calc_branch_rates(model.impl(), s, fresh);
      calc_branch_rates(model.impl(), s, reused);
      ASSERT_EQ(fresh.r.size(), reused.r.size()) << name;
      for (int i = 0; i < fresh.r.size(); ++i) {
        EXPECT_EQ(fresh.r[i], reused.r[i]) << name << " " << k << " " << i;
        EXPECT_EQ(fresh.b[i], reused.b[i]) << name << " " << k << " " << i;
      }
      EXPECT_EQ(fresh.conditioning, reused.conditioning) << name;
      EXPECT_EQ(fresh.J.free_cols, reused.J.free_cols) << name;
      EXPECT_EQ(fresh.ls.has_value(), reused.ls.has_value()) << name;
      ASSERT_EQ(fresh.J.G.nrow(), reused.J.G.nrow()) << name;
      for (int r = 0; r < fresh.J.G.nrow(); ++r)
        for (int c = 0; c < fresh.J.G.ncol(); ++c) EXPECT_EQ(fresh.J.G(r, c), reused.J.G(r, c)) << name;
    }
  }
}

}  // namespace
}  // namespace rdyn::engine
