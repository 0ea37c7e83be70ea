#include "validate/harness/verdicts.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/validate/harness/run_records.hpp"

namespace rdyn::validate {
namespace {

using test::record;

// Every row is read on the one recommended run (issue #23: a 10° run's errors once stood in the
// same table); the scene's thresholds are not mixed in.
TEST(Verdicts, EveryRowIsTheRecommendedRunAgainstTheTarget) {
  const RunRecord rec = record("reduced", 1e-3, {{"qdot", 2e-4}, {"F", 3e-3}, {"mean_qdot", 1e-6}});
  const auto v = calc_verdicts({"qdot", "F", "mean_qdot"}, &rec, 1e-3);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].quantity, "qdot");
  EXPECT_DOUBLE_EQ(v[0].error, 2e-4);
  EXPECT_DOUBLE_EQ(v[0].target, 1e-3);
  EXPECT_TRUE(v[0].within_target);
  EXPECT_DOUBLE_EQ(v[1].error, 3e-3);
  EXPECT_FALSE(v[1].within_target);
  EXPECT_TRUE(v[2].within_target);
  // Without a recommended setting nothing is within the target.
  const auto none = calc_verdicts({"qdot"}, nullptr, 1e-3);
  EXPECT_FALSE(none[0].within_target);
  EXPECT_TRUE(std::isinf(none[0].error));
}

// The full run the recommended setting is compared with is at least as accurate on every
// quantity it was chosen on: a cheaper run better on one and worse on the other is not it, and
// a stopped run never is.
TEST(Verdicts, MatchedFullRunIsTheCheapestAtEqualOrBetterError) {
  const RunRecord rec = record("reduced", 1e-3, {{"qdot", 2e-4}, {"F", 4e-4}});
  std::vector<RunRecord> runs{record("full", 2.0, {{"qdot", 1e-6}, {"F", 1e-6}}),
                              record("full", 0.9, {{"qdot", 2e-4}, {"F", 3e-4}}),   // equal on qdot: it
                              record("full", 0.5, {{"qdot", 1e-5}, {"F", 5e-4}}),   // worse on F
                              record("full", 0.1, {{"qdot", 1e-7}, {"F", 1e-7}}), rec};
  runs[3].failure = "stopped";
  EXPECT_EQ(pick_matched_full(rec, runs, {"qdot", "F"}), 1);
  // On the speed alone the cheaper run qualifies.
  EXPECT_EQ(pick_matched_full(rec, runs, {"qdot"}), 2);
  // None as accurate: −1 (the reference stands in).
  const RunRecord exact = record("reduced", 1e-3, {{"qdot", 0.0}, {"F", 0.0}});
  EXPECT_EQ(pick_matched_full(exact, runs, {"qdot", "F"}), -1);
}

// None as accurate: the floor is the run whose worst error ratio to the recommended run's is
// smallest — not the most accurate on one quantity, and never a stopped run.
TEST(Verdicts, MostAccurateFullRunIsTheSmallestWorstRatio) {
  const RunRecord rec = record("reduced", 1e-3, {{"qdot", 1e-6}, {"F", 1e-5}});
  std::vector<RunRecord> runs{record("full", 2.0, {{"qdot", 2e-6}, {"F", 1e-3}}),  // ratios 2, 100
                              record("full", 0.9, {{"qdot", 1e-5}, {"F", 5e-5}}),  // ratios 10, 5: it
                              record("full", 0.1, {{"qdot", 1e-7}, {"F", 1e-7}}), rec};
  runs[2].failure = "stopped";
  EXPECT_EQ(pick_matched_full(rec, runs, {"qdot", "F"}), -1);
  EXPECT_EQ(pick_most_accurate_full(rec, runs, {"qdot", "F"}), 1);
  EXPECT_EQ(pick_most_accurate_full(rec, runs, {"qdot"}), 0);
  runs.resize(1);
  runs[0].failure = "stopped";
  EXPECT_EQ(pick_most_accurate_full(rec, runs, {"qdot"}), -1);
  const std::vector<RunRecord> two{record("full", 0.9, {}), record("full", 0.5, {})};
  auto b = calc_baselines(rec, record("full", 4.0, {}), two, 0, false);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[1].what, "most accurate full run (less accurate)");
  EXPECT_EQ(b[2].what, "cheapest full run");
  // The compared run is the cheapest too: one row that says both (it was listed twice).
  b = calc_baselines(rec, record("full", 4.0, {}), two, 1, false);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b[1].what, "most accurate full run (less accurate), also the cheapest full run");
}

TEST(Verdicts, BaselinesAreCostRatios) {
  const RunRecord rec = record("reduced", 0.01, {{"qdot", 1e-4}});
  const RunRecord ref = record("full", 4.0, {{"qdot", 0.0}});
  std::vector<RunRecord> runs{record("full", 2.0, {{"qdot", 1e-5}}),
                              record("full", 0.5, {{"qdot", 1e-3}}), rec};
  runs.push_back(record("full", 0.1, {}));
  runs.back().failure = "stopped";  // not a baseline
  const auto b = calc_baselines(rec, ref, runs, 0);
  ASSERT_EQ(b.size(), 3u);
  EXPECT_EQ(b[0].what, "reference");
  EXPECT_DOUBLE_EQ(b[0].speedup, 400);
  EXPECT_EQ(b[1].what, "full run at equal or better error");
  EXPECT_DOUBLE_EQ(b[1].speedup, 200);
  EXPECT_EQ(b[2].what, "cheapest full run");
  EXPECT_DOUBLE_EQ(b[2].speedup, 50);
}

TEST(Verdicts, ErrorBudgetSeparatesTableAndIntegration) {
  RunRecord fast = record("reduced", 0.001, {{"F", 5e-4}});
  fast.integrator = "rk4-fixed";
  fast.tolerance = 0;
  RunRecord tight = record("reduced", 0.01, {{"F", 2e-4}});
  tight.tolerance = 1e-10;
  RunRecord other_grid = tight;
  other_grid.grid_deg = 5;
  other_grid.errors.signals[0].max_rel = 1e-7;
  const auto b = calc_error_budget(fast, {other_grid, tight, fast}, 1e-9, "F", 1e-10);
  EXPECT_DOUBLE_EQ(b.reference, 1e-9);
  EXPECT_DOUBLE_EQ(b.table, 2e-4);
  EXPECT_DOUBLE_EQ(b.integration, 3e-4);
  EXPECT_DOUBLE_EQ(b.total, 5e-4);
  EXPECT_EQ(b.table_run, tight.label());
  // No tight run at that grid: the table share is unknown, not zero.
  EXPECT_TRUE(std::isnan(calc_error_budget(fast, {other_grid}, 1e-9, "F", 1e-10).table));
  // Output interpolation is measured on the run itself, apart from the total; unknown when
  // the run has no Hermite rows compared.
  EXPECT_TRUE(std::isnan(b.output_interpolation));
  fast.output_interpolation.signals = {{"qdot", 1.0, 7e-9, 1e-9}, {"F", 1.0, 3e-6, 1e-6}};
  const auto c = calc_error_budget(fast, {tight, fast}, 1e-9, "F", 1e-10);
  EXPECT_DOUBLE_EQ(c.output_interpolation, 3e-6);
  EXPECT_DOUBLE_EQ(c.total, 5e-4);
}

}  // namespace
}  // namespace rdyn::validate
