// Forward dynamics: energy balance, closed-form motion, and equivalent model variants.
#include "engine/forward_dynamics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "models/scene_yaml.hpp"
#include "test_scenes.hpp"

namespace rdyn::engine {
namespace {

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

TEST(ForwardDynamics, EnergyBalanceClosesOnEveryShippedScene) {
  for (const char* name : {"bicycle", "fourbar", "slider-crank"}) {
    const auto scene = models::load_scene(name);
    FullModel model(scene);
    ForwardOptions opt;
    opt.duration_s = scene.simulation.duration_s;
    opt.output_interval_s = 0.01;
    opt.tolerance = scene.simulation.tolerance;
    const auto ts = simulate_full(model, opt);
    double residual = 0;
    for (size_t i = 0; i < ts.t.size(); ++i)
      residual = std::max(residual, std::abs(ts.energy[i] - ts.energy[0] - ts.work[i]));
    // E(t) − E(0) = W(t): work of the non-conservative loads, integrated separately.
    EXPECT_LT(residual, 1e-6 * max_abs(ts.energy)) << name;
    EXPECT_GT(max_abs(ts.work), 1e-3 * max_abs(ts.energy)) << name << ": loads must do work";
    EXPECT_LT(ts.stats.max_constraint_error, 1e-8) << name;
  }
}

TEST(ForwardDynamics, ParallelogramFollowsConstantInertiaClosedForm) {
  // m1 constant and m2 = 0: q(t) = q0 + ω0 t + ½ (T/m1) t².
  const double T = 0.05;
  const auto scene = models::parse_scene(test::parallelogram_yaml(T, false), "p.yaml");
  FullModel model(scene);
  ForwardOptions opt;
  opt.duration_s = 1.0;
  opt.output_interval_s = 0.05;
  opt.tolerance = 1e-10;
  const auto ts = simulate_full(model, opt);
  const double a = T / test::parallelogram_m1();
  for (size_t i = 0; i < ts.t.size(); ++i) {
    const double t = ts.t[i];
    EXPECT_NEAR(ts.q[i], scene.initial.q + scene.initial.qdot * t + 0.5 * a * t * t, 1e-8) << t;
    EXPECT_NEAR(ts.qddot[i], a, 1e-7 * a) << t;  // constraint tolerance 1e-10 limits this
  }
}

TEST(ForwardDynamics, KneeForceRoutesAgreeAlongTheTrajectory) {
  const auto scene = models::load_scene("bicycle");
  FullModelOptions reaction;
  reaction.route = ConstraintForceRoute::Reaction;
  FullModel act(scene), rea(scene, reaction);
  ForwardOptions opt;
  opt.duration_s = 1.0;
  opt.output_interval_s = 0.01;
  const auto a = simulate_full(act, opt), r = simulate_full(rea, opt);
  const double peak = max_abs(r.forces[0]);
  for (size_t i = 0; i < a.t.size(); ++i) {
    EXPECT_NEAR(a.qdot[i], r.qdot[i], 1e-7 * std::abs(r.qdot[i])) << a.t[i];
    EXPECT_NEAR(a.forces[0][i], r.forces[0][i], 1e-6 * peak) << a.t[i];
  }
}

TEST(ForwardDynamics, FoldedFlywheelMatchesGearedFlywheelBody) {
  // Folding the flywheel onto the crank (r² I) must not change the motion compared with
  // simulating it as its own body held by a gear constraint.
  const auto folded = models::load_scene("bicycle");
  auto body = folded;
  body.outputs.bodies.push_back("flywheel");
  FullModel mf(folded), mb(body);
  EXPECT_TRUE(mf.is_folded("flywheel"));
  EXPECT_FALSE(mb.is_folded("flywheel"));
  EXPECT_EQ(mb.num_simbody_bodies(), mf.num_simbody_bodies() + 1);
  ForwardOptions opt;
  opt.duration_s = 1.5;
  opt.output_interval_s = 0.05;
  const auto a = simulate_full(mf, opt), b = simulate_full(mb, opt);
  for (size_t i = 0; i < a.t.size(); ++i) {
    EXPECT_NEAR(a.qdot[i], b.qdot[i], 1e-7 * std::abs(b.qdot[i])) << a.t[i];
    EXPECT_NEAR(a.energy[i], b.energy[i], 1e-7 * std::abs(b.energy[i])) << a.t[i];
    EXPECT_NEAR(a.forces[0][i], b.forces[0][i], 1e-5 * max_abs(b.forces[0])) << a.t[i];
  }
}

TEST(ForwardDynamics, HipTorqueActsOnlyWhileTheThighDescends) {
  // With the resistance off, kinetic energy rises only through the gated hip torques:
  // the work is non-decreasing and grows by about 2·T·Δθ_thigh per revolution.
  const auto scene = models::load_scene("bicycle", {models::parse_override("bicycle_leg.resistance.power_W=0")});
  FullModel model(scene);
  ForwardOptions opt;
  opt.duration_s = 1.0;
  opt.output_interval_s = 0.002;
  const auto ts = simulate_full(model, opt);
  for (size_t i = 1; i < ts.t.size(); ++i) EXPECT_GE(ts.work[i], ts.work[i - 1] - 1e-9) << ts.t[i];
  EXPECT_GT(ts.work.back(), 50.0);
}

}  // namespace
}  // namespace rdyn::engine
