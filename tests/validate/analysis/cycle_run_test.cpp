// The cycle the reports animate: the last whole revolution of a run found against closed forms
// (a uniform turn, a rocking coordinate), and the re-run from its start against the long run it
// was taken from (two Simbody runs: the same motion to the integrator's tolerance) with its
// loops closed where models::calc_pose places the bodies.
#include "validate/analysis/cycle_run.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "models/pose.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/mechanism_run.hpp"

namespace rdyn::validate {
namespace {

models::TimeSeries series(double dt, double t_end, double (*q)(double), double (*qdot)(double)) {
  models::TimeSeries ts;
  for (int i = 0; i * dt <= t_end + 1e-12; ++i) {
    const double t = i * dt;
    ts.t.push_back(t), ts.q.push_back(q(t)), ts.qdot.push_back(qdot(t));
  }
  return ts;
}

// q = 2π·1.3·t (and turning the other way): revolutions end at k/1.3 s; the last whole one of
// 5 s is [5/1.3, 6/1.3] = [3.846…, 4.615…] s.
TEST(CycleRun, LastWholeRevolutionOfAUniformTurn) {
  for (double sign : {1.0, -1.0}) {
    static double s;
    s = sign;
    const auto ts = series(0.01, 5.0, [](double t) { return s * 2 * M_PI * 1.3 * t; },
                           [](double) { return s * 2 * M_PI * 1.3; });
    const CycleStart c = calc_last_cycle(ts, 0.5);
    EXPECT_NEAR(c.duration_s, 1 / 1.3, 1e-12) << sign;
    // The first row at or after 5/1.3 = 3.84615 s: 3.85 s, its state exactly.
    EXPECT_NEAR(c.t_s, 3.85, 1e-12) << sign;
    EXPECT_EQ(c.q, ts.q[385]);
    EXPECT_EQ(c.qdot, ts.qdot[385]);
    EXPECT_TRUE(c.revolution);
  }
}

// q = 0.3 sin t never turns: the last `fallback_s` of the run, or the whole run when shorter.
TEST(CycleRun, ARockingCoordinateGivesTheRunsLastPeriod) {
  const auto ts = series(0.01, 4.0, [](double t) { return 0.3 * std::sin(t); }, [](double t) { return 0.3 * std::cos(t); });
  const CycleStart c = calc_last_cycle(ts, 1.5);
  EXPECT_NEAR(c.t_s, 2.5, 1e-12);
  EXPECT_NEAR(c.duration_s, 1.5, 1e-12);
  EXPECT_EQ(c.q, ts.q[250]);
  EXPECT_FALSE(c.revolution);
  const CycleStart whole = calc_last_cycle(ts, 10.0);
  EXPECT_EQ(whole.t_s, 0.0);
  EXPECT_NEAR(whole.duration_s, 4.0, 1e-12);
  EXPECT_THROW(calc_last_cycle(ts, 0.0), std::invalid_argument);
  models::TimeSeries one;
  one.t = {0}, one.q = {0}, one.qdot = {1};
  EXPECT_THROW(calc_last_cycle(one, 1.0), std::invalid_argument);
}

// Cubic Hermite of (q, q̇) between the rows of `ts` around t.
double q_at(const models::TimeSeries& ts, double t) {
  size_t i = 0;
  while (i + 2 < ts.t.size() && ts.t[i + 1] <= t) ++i;
  const double h = ts.t[i + 1] - ts.t[i], x = (t - ts.t[i]) / h, x2 = x * x, x3 = x2 * x;
  return (2 * x3 - 3 * x2 + 1) * ts.q[i] + (x3 - 2 * x2 + x) * h * ts.qdot[i] + (-2 * x3 + 3 * x2) * ts.q[i + 1] +
         (x3 - x2) * h * ts.qdot[i + 1];
}

// The four-bar without gravity turns on, slowed by its bearing (~3.5 revolutions in 3 s; with
// gravity it swings back and forth and has no whole revolution).
TEST(CycleRun, TheFourbarsLastRevolutionRerunIsTheLongRunsMotion) {
  const auto s = models::load_scene("fourbar", {models::parse_override("gravity.enabled=false")});
  const auto run = simulate_every_joint(s, "full", 3.0, 0.002);
  const CycleStart c = calc_last_cycle(run, 1.0);
  ASSERT_GT(c.t_s, 0.5);
  const auto cyc = simulate_cycle(s, c);
  ASSERT_EQ(cyc.t.size(), static_cast<size_t>(kCycleIntervals + 1));
  EXPECT_EQ(cyc.t.front(), c.t_s);
  EXPECT_NEAR(cyc.t.back(), c.t_s + c.duration_s, 1e-12);
  EXPECT_EQ(cyc.q.front(), c.q);
  // One whole revolution — to the start's offset from the crossing (at most one 2 ms row at
  // ~8 rad/s) times the slowing over the turn — and the same motion as the long run's at the
  // same times.
  EXPECT_NEAR(cyc.q.back() - cyc.q.front(), 2 * M_PI, 2e-3);
  for (size_t r = 0; r < cyc.t.size(); ++r)
    if (cyc.t[r] <= run.t.back()) {
      EXPECT_NEAR(cyc.q[r], q_at(run, cyc.t[r]), 1e-6) << "t = " << cyc.t[r];
    }
  // Every row's joint coordinates close the loop.
  for (size_t r = 0; r < cyc.t.size(); ++r) {
    const auto pose = models::calc_pose(s, joint_coordinates(s, cyc, r));
    for (const auto& l : s.loops) {
      const auto a = models::calc_ground_point(s, pose, l.body_a, l.point_a);
      const auto b = models::calc_ground_point(s, pose, l.body_b, l.point_b);
      EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 1e-8) << l.name << " row " << r;
    }
  }
}

}  // namespace
}  // namespace rdyn::validate
