#include "validate/harness/ladder_plan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

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
  // Fixed steps about 1.2 apart from period/50 to the cap of duration/100 = 50 ms (period/18 and
  // period/15 both capped there): the cheap corner of RK4 resolved to about 2× in error (bicycle:
  // 28.2 ms 3.2e-5, 39.4 ms 1.6e-4).
  EXPECT_EQ(p.fixed_steps_s.size(), 11u);
  EXPECT_NEAR(p.fixed_steps_s[6], 1.0 / 35, 1e-15);  // period 1 s
  EXPECT_NEAR(p.fixed_steps_s.back(), 5.0 / kMinFixedSteps, 1e-15);
  // 7 grids × 6 variants × (3 rk8pd + rkck + 11 rk4).
  EXPECT_EQ(p.reduced_runs(), 7 * 6 * 15);
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

TEST(LadderPlan, TheDefaultGridIsAlwaysRun) {
  const TimeScale one_second{1.0, 5.0, ""};
  const auto q = plan_ladders(one_second, true);
  // 2.5° (a five-bar geared 6:1) joins the quick ladder in its place, coarse to fine; a grid the
  // ladder has is not run twice.
  const auto with = with_grid(q, 2.5);
  EXPECT_EQ(with.grids_deg, (std::vector<double>{30, 10, 5, 2.5}));
  EXPECT_EQ(with.reduced_runs(), 4 * 2 * 2);
  EXPECT_EQ(with_grid(q, 10.0).grids_deg, q.grids_deg);
  EXPECT_EQ(with_grid(plan_ladders(one_second, false), 1.25).grids_deg,
            (std::vector<double>{30, 20, 10, 5, 2, 1.25, 1, 0.5}));
}

TEST(LadderPlan, FixedStepsFollowTheTimeScale) {
  // A 30 ms transient: every fixed step leaves at least kMinFixedSteps steps.
  const auto p = plan_ladders({0.008, 0.03, ""}, false);
  for (double h : p.fixed_steps_s) EXPECT_LE(h, 0.03 / kMinFixedSteps * (1 + 1e-12));
  EXPECT_NEAR(p.fixed_steps_s.front(), 0.008 / 1000, 1e-15);
}

}  // namespace
}  // namespace rdyn::validate
