// The run-level check of a default grid: the reduced run on the grid the table checks chose
// (extract_resolving: m1, Q_cons and the constraint lines resolved) against the run on half that
// grid, both carried through the same motion. A table can resolve every column and still give a
// run off by more than its columns are: a Whitworth quick-return nearly stops once a turn (0.34
// rad/s of 26), so a column error of 2e-7 of its peak moved the slow stretch's timing and the 5°
// run's block moment came out 1.7e-3 off, where the 2.5° run is within 5e-5; the shipped
// bicycle's 10° knee force is 1.7e-3 off near the straight leg, the 5° one 1.8e-6.
#pragma once

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#include <nlohmann/json.hpp>

#include "models/timeseries.hpp"

namespace rdyn::validate {

// Above this change of some column between the runs on h and h/2 (of that column's peak), the
// h run is not kept: half the 1e-3 of every output column's scale, so the kept run's own
// error (about its change, the finer run being far closer) stays inside 1e-3. Measured changes
// at the grids the table checks choose: the fourbar 1.8e-7, slider-crank 2.3e-10, thousand-cycles
// 2.8e-4 (1000 s: a phase), bicycle 1.7e-3 (so 5°), Whitworth 1.7e-3 (so 2.5°).
inline constexpr double kGridCheckMaxChange = 5e-4;
// The finest grid a check runs: the table checks stop at 0.3125°, whose run is compared with one
// at half that; the hard high-saddle bicycle (an almost straight leg) still changes 5.3e-2 there,
// and the finer run (9.5e-4 of the full model) is kept with a warning.
inline constexpr double kMinGridCheck_deg = 0.15625;

struct GridCheck {
  double grid_deg = 0.0;        // the grid of the run kept
  double finer_grid_deg = 0.0;  // the grid it was last compared with (0: none)
  double coarser_grid_deg = 0.0;  // unconverged: the grid the kept run was compared with
  std::string column;           // the column that changed most in that comparison
  double change = NAN;          // its max |finer − coarser| over the run, of the finer run's peak
  bool verified = false;        // the kept run changed at most kGridCheckMaxChange on half its grid
  std::string not_compared;     // a finer run that failed: why (the kept run is not checked)
};

// The check as run.json and summary.json record it (null for a grid not compared or a change
// not measured).
nlohmann::json grid_check_json(const GridCheck& check);

// The largest change between two runs over the columns validate compares (qdot, constraint
// forces, joint outputs; compare_series's rules: from t = 0, rows where a load gate differs left
// out, a joint output zero but for rounding scaled by 1e-9 of the largest), with its column.
std::pair<std::string, double> calc_run_change(const models::TimeSeries& finer, const models::TimeSeries& coarser);

// From `kept`, the run on `grid_deg`: while the run on half the grid (run_at(grid), an R with
// a member `ts`) changes some column by more than kGridCheckMaxChange, the finer run is kept
// and the check repeated, down to a finer run on kMinGridCheck_deg. Returns the run kept: the
// coarsest one verified, or the finest one run (check.verified false). A finer run that fails
// (a std::runtime_error) ends the check with the run kept so far. `say`: each step on standard
// error.
template <class R, class RunAt>
R check_grid_by_runs(R kept, double grid_deg, const RunAt& run_at, bool say, GridCheck& check) {
  check = GridCheck{};
  check.grid_deg = grid_deg;
  while (grid_deg / 2 >= kMinGridCheck_deg - 1e-9) {
    R finer;
    try {
      finer = run_at(grid_deg / 2);
    } catch (const std::runtime_error& e) {
      check.not_compared = e.what();
      return kept;
    }
    const auto [column, change] = calc_run_change(finer.ts, kept.ts);
    check.finer_grid_deg = grid_deg / 2;
    check.column = column;
    check.change = change;
    if (change <= kGridCheckMaxChange) {  // a NaN change is not a pass
      check.verified = true;
      return kept;
    }
    if (say)
      std::fprintf(stderr,
                   "rdyn: the reduced run on the %g° table changes %s by %.2g %% of its peak on half the grid: taking "
                   "the %g° table\n",
                   grid_deg, column.c_str(), 100 * change, grid_deg / 2);
    kept = std::move(finer);
    check.coarser_grid_deg = grid_deg;
    grid_deg /= 2;
    check.grid_deg = grid_deg;
    check.finer_grid_deg = 0;
  }
  return kept;
}

}  // namespace rdyn::validate
