#include "validate/harness/pareto.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/validate/harness/run_records.hpp"

namespace rdyn::validate {
namespace {

using test::record;

std::vector<RunRecord> ladder() {
  return {
      record("full", 1.0, {{"qdot", 1e-6}, {"F", 1e-6}}),  // 0: accurate, slow
      record("full", 0.2, {{"qdot", 5e-4}, {"F", 8e-4}}),  // 1: within 1e-3, cheapest such
      record("full", 0.1, {{"qdot", 1e-2}, {"F", 2e-2}}),  // 2: cheap, outside the target
      record("reduced", 0.002,
             {{"qdot", 1e-4}, {"F", 9e-4}}),  // 3: cheap, F worse than run 1's 8e-4
      record("reduced", 0.004, {{"qdot", 1e-5}, {"F", 7e-4}}),  // 4: matches run 1
      record("reduced", 0.005, {{"qdot", 1e-5}, {"F", 7e-4}}),  // 5: dominated by 4
      record("reduced", 0.001, {{"qdot", 2e-3}, {"F", 3e-3}}),  // 6: cheapest, outside the target
  };
}

TEST(Pareto, FrontPerModel) {
  auto runs = ladder();
  runs.push_back(record("reduced", 0.0005, {{"qdot", 1e-9}, {"F", 1e-9}}));
  runs.back().failure = "diverged";  // a stopped run is on no front and dominates nothing
  runs.back().errors.signals.clear();
  mark_pareto(runs, "F");
  const std::vector<bool> expected{true, true, true, true, true, false, true, false};
  for (size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].pareto, expected[i]) << i;
}

TEST(Pareto, MatchedSpeedupTakesTheCheapestOnBothSides) {
  const auto runs = ladder();
  const auto m = calc_matched_speedup(runs, "F", 1e-3);
  EXPECT_EQ(m.full, 1);
  EXPECT_EQ(m.reduced, 4);  // run 3 is cheaper but its F error 9e-4 exceeds the full run's 8e-4
  ASSERT_TRUE(m.speedup);
  EXPECT_DOUBLE_EQ(*m.speedup, 0.2 / 0.004);
  // A target no full run reaches: nothing is claimed.
  const auto none = calc_matched_speedup(runs, "F", 1e-7);
  EXPECT_EQ(none.full, -1);
  EXPECT_FALSE(none.speedup);
}

// A peer engine is a baseline like the full model: its runs only, never the full model's.
TEST(Pareto, MatchedSpeedupAgainstAPeerUsesThePeersRunsOnly) {
  auto runs = ladder();
  runs.push_back(record("mujoco", 0.05, {{"qdot", 1e-4}, {"F", 9.5e-4}}));  // 7: within 1e-3
  runs.push_back(record("mujoco", 0.01, {{"qdot", 1e-3}, {"F", 5e-3}}));    // 8: outside
  const auto m = calc_matched_speedup(runs, "F", 1e-3, "mujoco");
  EXPECT_EQ(m.full, 7);
  EXPECT_EQ(m.reduced, 3);  // 9e-4 ≤ 9.5e-4: the cheapest as accurate
  ASSERT_TRUE(m.speedup);
  EXPECT_DOUBLE_EQ(*m.speedup, 0.05 / 0.002);
  EXPECT_EQ(calc_matched_speedup(runs, "F", 1e-3).full, 1);  // the default baseline is still the full model
}

TEST(Pareto, RecommendedIsTheCheapestWithinTheTargetOnEveryQuantity) {
  const auto runs = ladder();
  EXPECT_EQ(pick_recommended(runs, {"qdot", "F"}, 1e-3), 3);
  EXPECT_EQ(pick_recommended(runs, {"qdot", "F"}, 8e-4), 4);
  EXPECT_EQ(pick_recommended(runs, {"qdot", "F"}, 1e-8), -1);
  EXPECT_EQ(pick_recommended(runs, {"qdot", "missing"}, 1.0),
            -1);  // an unmeasured quantity never passes
}

}  // namespace
}  // namespace rdyn::validate
