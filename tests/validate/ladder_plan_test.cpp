#include "validate/ladder_plan.hpp"

#include <gtest/gtest.h>

#include <algorithm>

namespace rdyn::validate {
namespace {

TEST(LadderPlan, FullAndQuickLadders) {
  const TimeScale one_second{1.0, 5.0, ""};
  const auto p = plan_ladders(one_second, false);
  EXPECT_EQ(p.full.size(), 13u);
  for (const char* integrator : {"rkmerson", "rk3", "cpodes"})  // every Simbody integrator has a ladder
    EXPECT_GE(std::count_if(p.full.begin(), p.full.end(), [&](const auto& f) { return f.first == integrator; }), 3)
        << integrator;
  EXPECT_TRUE(p.time_full_without_outputs);  // fair baseline: the output grid does not cap the step
  EXPECT_EQ(p.grids_deg.front(), 30);
  EXPECT_EQ(p.grids_deg.back(), 0.5);
  EXPECT_EQ(p.tightest_tolerance(), 1e-10);
  // Fixed steps about √2 apart from period/100 to period/25: the cheap corner of RK4 between
  // an error within the matched target and one beyond it (bicycle: 19.7 ms 6.9e-6, 39.4 ms 1.6e-4).
  EXPECT_EQ(p.fixed_steps_s.size(), 7u);
  EXPECT_NEAR(p.fixed_steps_s[5], 1.0 / 35, 1e-15);  // period 1 s
  // 7 grids × 6 variants × (3 rk8pd + rkck + 7 rk4).
  EXPECT_EQ(p.reduced_runs(), 7 * 6 * 11);
  EXPECT_TRUE(p.time_reduced_without_outputs);  // one timing rule for every engine
  EXPECT_TRUE(p.time_peers_without_outputs);
  EXPECT_EQ(p.extraction_repeats_10deg, 3);
  EXPECT_GE(p.full_repeats.min_repeats, 3);
  EXPECT_GT(p.reduced_repeats.min_total_s, 0);
  const auto q = plan_ladders(one_second, true);
  EXPECT_EQ(q.reduced_runs(), 3 * 2 * 2);  // 3 grids × 2 variants × (rk8pd + one rk4)
  EXPECT_EQ(q.full_repeats.min_repeats, 1);
  EXPECT_EQ(q.tightest_tolerance(), 1e-8);
}

TEST(LadderPlan, FixedStepsFollowTheTimeScale) {
  // A 30 ms transient: every fixed step leaves at least kMinFixedSteps steps.
  const auto p = plan_ladders({0.008, 0.03, ""}, false);
  for (double h : p.fixed_steps_s) EXPECT_LE(h, 0.03 / kMinFixedSteps * (1 + 1e-12));
  EXPECT_NEAR(p.fixed_steps_s.front(), 0.008 / 1000, 1e-15);
}

}  // namespace
}  // namespace rdyn::validate
