// The ladder's fixed steps follow the scene's time scale (issue #14: a 30 ms transient got the
// 1–40 ms ladder of a 1 s cycle, with 1-step rows that "diverged").
#include "validate/harness/time_scale.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rdyn::validate {
namespace {

// Constant speed w over T seconds.
models::TimeSeries spinning(double w, double T, int n = 1000) {
  models::TimeSeries ts;
  for (int i = 0; i <= n; ++i) {
    const double t = T * i / n;
    ts.t.push_back(t);
    ts.q.push_back(w * t);
    ts.qdot.push_back(w);
  }
  return ts;
}

TEST(TimeScale, OneRevolutionAtThePeakSpeed) {
  const auto s = calc_time_scale(spinning(2 * M_PI, 5.0), true);
  EXPECT_NEAR(s.period_s, 1.0, 1e-12);  // 1 rev/s
  EXPECT_NEAR(s.duration_s, 5.0, 1e-12);
  // A 1 s cycle: 1, 5, 10 ms, 1/70 s, 20 ms, then rungs about 1.2 apart (where the matched-error
  // RK4 setting lies) up to the cap of duration/100 = 50 ms, which period/18 and period/15 share.
  const auto h = calc_fixed_step_ladder(s, false);
  const std::vector<double> expected{1e-3, 5e-3,      1e-2, 1.0 / 70, 2e-2,     1.0 / 42,
                                     1.0 / 35, 1.0 / 30, 4e-2, 1.0 / 21, 5.0 / kMinFixedSteps};
  ASSERT_EQ(h.size(), expected.size());
  for (size_t i = 0; i < h.size(); ++i) EXPECT_NEAR(h[i], expected[i], 1e-15);
  EXPECT_EQ(calc_fixed_step_ladder(s, true), std::vector<double>{5e-3});
}

// MuJoCo's ladder: 0.1, 0.33, 1, 3.3 ms for a 1 s cycle; capped like the reduced ladder.
TEST(TimeScale, PeerLadderIsTenTimesFinerAndCappedTheSameWay) {
  const auto s = calc_time_scale(spinning(2 * M_PI, 5.0), true);
  const auto h = calc_peer_step_ladder(s, false);
  const std::vector<double> expected{1e-4, 1.0 / 3000, 1e-3, 1.0 / 300};
  ASSERT_EQ(h.size(), expected.size());
  for (size_t i = 0; i < h.size(); ++i) EXPECT_NEAR(h[i], expected[i], 1e-15);
  EXPECT_EQ(calc_peer_step_ladder(s, true), std::vector<double>{1e-3});
  const auto slow = calc_time_scale(spinning(0.5, 2.0), true);  // no revolution: period = 2 s
  for (double step : calc_peer_step_ladder(slow, false)) EXPECT_LE(step, 2.0 / kMinFixedSteps * (1 + 1e-12));
}

TEST(TimeScale, ShortTransientTakesEnoughStepsInEveryRun) {
  // 30 ms at up to 800 rad/s (the squeezing mechanism): period ≈ 7.9 ms.
  const auto s = calc_time_scale(spinning(800.0, 0.03), true);
  EXPECT_NEAR(s.period_s, 2 * M_PI / 800, 1e-12);
  const auto h = calc_fixed_step_ladder(s, false);
  ASSERT_FALSE(h.empty());
  for (double step : h) {
    EXPECT_GE(0.03 / step, kMinFixedSteps * (1 - 1e-12)) << step;
    EXPECT_LE(step, s.period_s / 15 * (1 + 1e-12));
  }
  for (size_t i = 1; i < h.size(); ++i) EXPECT_LT(h[i - 1], h[i]);  // ascending, no duplicates
  EXPECT_FALSE(per_second_is_measured(0.03));
  EXPECT_TRUE(per_second_is_measured(5.0));
}

TEST(TimeScale, WithoutARevolutionTheDurationSetsTheScale) {
  // Rocking, or too slow to turn once: the run's duration.
  auto s = calc_time_scale(spinning(0.5, 2.0), true);
  EXPECT_NEAR(s.period_s, 2.0, 1e-12);
  EXPECT_NE(s.how.find("duration"), std::string::npos);
  s = calc_time_scale(spinning(2 * M_PI, 5.0), false);  // prismatic coordinate
  EXPECT_NEAR(s.period_s, 5.0, 1e-12);
  // The steps are capped at duration / kMinFixedSteps, so even the coarsest one resolves the run.
  for (double step : calc_fixed_step_ladder(s, false))
    EXPECT_LE(step, 5.0 / kMinFixedSteps * (1 + 1e-12));
}

}  // namespace
}  // namespace rdyn::validate
