// The run-level grid check on synthetic runs whose grid error is known: a fourth-order one
// (a cubic-like table), one that never converges, and a finer run that fails.
#include "validate/harness/grid_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace rdyn::validate {
namespace {

struct GridRun {
  models::TimeSeries ts;
};

// A run whose every compared column is its exact value times (1 + e): qdot = cos t, the force
// F_rod = 50 sin t, the joint output R_pin_x = 20 cos 2t, over 2 s.
GridRun run_with_error(double e) {
  GridRun r;
  r.ts.force_names = {"rod"};
  r.ts.forces.resize(1);
  r.ts.column_names = {"R_pin_x"};
  r.ts.columns.resize(1);
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.01 * i;
    r.ts.t.push_back(t);
    r.ts.q.push_back(std::sin(t));
    r.ts.qdot.push_back(std::cos(t) * (1 + e));
    r.ts.forces[0].push_back(50 * std::sin(t) * (1 + 2 * e));  // the force changes most
    r.ts.columns[0].push_back(20 * std::cos(2 * t) * (1 + e));
  }
  return r;
}

TEST(GridCheck, RunChangeIsTheLargestColumnChangeNamedAsItsCsvColumn) {
  const GridRun a = run_with_error(0.0), b = run_with_error(1e-3);
  auto [column, change] = calc_run_change(a.ts, b.ts);
  EXPECT_EQ(column, "F_rod");
  EXPECT_NEAR(change, 2e-3, 1e-12);  // of the force's peak, 50 · max|sin t| over [0, 2]
  GridRun c = run_with_error(0.0);
  c.ts.columns[0][17] += 0.2;  // 1 % of the joint output's peak 20
  std::tie(column, change) = calc_run_change(a.ts, c.ts);
  EXPECT_EQ(column, "R_pin_x");
  EXPECT_NEAR(change, 1e-2, 1e-12);
  c.ts.qdot[3] = NAN;  // a NaN is the largest change there is, never a pass
  std::tie(column, change) = calc_run_change(a.ts, c.ts);
  EXPECT_EQ(column, "qdot");
  EXPECT_TRUE(std::isnan(change));
}

// Error 1e-6 h⁴ (h in degrees): the change from h to h/2 is 15/16 of the h run's error —
// 9.4e-3 at 10°, 5.9e-4 at 5° (both above 5e-4), 3.7e-5 at 2.5°: 2.5° is kept, verified on 1.25°.
TEST(GridCheck, TheCoarsestGridWhoseRunChangesLittleOnHalfItIsKept) {
  std::vector<double> asked;
  auto run_at = [&](double h) {
    asked.push_back(h);
    return run_with_error(1e-6 * std::pow(h, 4));
  };
  GridCheck check;
  const GridRun kept = check_grid_by_runs(run_at(10), 10, run_at, false, check);
  EXPECT_EQ(asked, (std::vector<double>{10, 5, 2.5, 1.25}));
  EXPECT_EQ(check.grid_deg, 2.5);
  EXPECT_EQ(check.finer_grid_deg, 1.25);
  EXPECT_EQ(check.coarser_grid_deg, 5);
  EXPECT_TRUE(check.verified);
  EXPECT_EQ(check.column, "F_rod");
  const double e25 = 1e-6 * std::pow(2.5, 4), e125 = 1e-6 * std::pow(1.25, 4);
  EXPECT_NEAR(check.change, 2 * (e25 - e125) / (1 + 2 * e125), 1e-12);
  EXPECT_NEAR(kept.ts.qdot[0], 1 + e25, 1e-15);  // the 2.5° run, not the finer one
  // A run that already changes little on half its grid is kept with one more run.
  asked.clear();
  check_grid_by_runs(run_at(1), 1, run_at, false, check);
  EXPECT_EQ(asked, (std::vector<double>{1, 0.5}));
  EXPECT_EQ(check.grid_deg, 1);
  EXPECT_TRUE(check.verified);
}

// An error that flips sign at every halving never converges: the finest run is kept, on
// kMinGridCheck_deg, and the check says it is not verified, with the last change.
TEST(GridCheck, ARunThatNeverConvergesKeepsTheFinestAndSaysSo) {
  int runs = 0;
  auto run_at = [&](double h) {
    ++runs;
    const int k = static_cast<int>(std::lround(std::log2(10 / h)));
    return run_with_error(k % 2 ? -5e-3 : 5e-3);
  };
  GridCheck check;
  const GridRun kept = check_grid_by_runs(run_at(10), 10, run_at, false, check);
  EXPECT_EQ(runs, 7);  // 10 … 0.15625
  EXPECT_EQ(check.grid_deg, kMinGridCheck_deg);
  EXPECT_EQ(check.coarser_grid_deg, 2 * kMinGridCheck_deg);
  EXPECT_EQ(check.finer_grid_deg, 0);
  EXPECT_FALSE(check.verified);
  EXPECT_NEAR(check.change, 2e-2 / (1 + 1e-2), 1e-9);  // F_rod: 1 ± 1e-2, of the finer run's peak
  EXPECT_NEAR(kept.ts.qdot[0], 1 + 5e-3, 1e-15);  // k = 6 at 0.15625°
}

TEST(GridCheck, AFinerRunThatFailsLeavesTheRunUnchecked) {
  auto run_at = [&](double h) -> GridRun {
    if (h < 5) throw std::runtime_error("the 2.5° table is not a model");
    return run_with_error(h == 5 ? 0.0 : 1e-2);
  };
  GridCheck check;
  const GridRun kept = check_grid_by_runs(run_at(10), 10, run_at, false, check);
  EXPECT_EQ(check.grid_deg, 5);  // 10° changed 2 % on 5°; 5° could not be compared
  EXPECT_FALSE(check.verified);
  EXPECT_EQ(check.not_compared, "the 2.5° table is not a model");
  EXPECT_NEAR(kept.ts.qdot[0], 1.0, 1e-15);
}

}  // namespace
}  // namespace rdyn::validate
