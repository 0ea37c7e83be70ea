// The first screen of a report: for each compared quantity, the error at the recommended
// reduced setting, the limit it is held to, pass or fail; the recommended run's speed against
// each full-model baseline; and where its error comes from.
#pragma once

#include <string>
#include <vector>

#include "validate/harness/run_record.hpp"

namespace rdyn::validate {

// One row of the first screen: a quantity's error at the recommended reduced setting against
// the validation's target. Every row is read on that one run (issue #23: the table once mixed
// the recommended run's errors with a 10° run's, so its two error columns disagreed); the
// scene's thresholds, each on the grid it declares, are judged separately (thresholds.hpp) and
// decide the status.
struct Verdict {
  std::string quantity;
  double error = 0.0;   // at the recommended setting (+∞ without one)
  double target = 0.0;  // the validation's matched-error target
  bool within_target = false;
};

std::vector<Verdict> calc_verdicts(const std::vector<std::string>& quantities,
                                   const RunRecord* recommended, double target);

// The full run the recommended setting is compared with: the cheapest completed full run whose
// error on every one of `quantities` is at most the recommended run's (equal or better error, so
// the speedup never flatters the reduced model); −1 when none is (the reference then stands in).
int pick_matched_full(const RunRecord& recommended, const std::vector<RunRecord>& runs,
                      const std::vector<std::string>& quantities);

// When none is: the completed full run closest to it, the least worst ratio of its error to the
// recommended run's over `quantities` (−1: no completed full run). The recommended run is both
// faster and more accurate than it, so its speedup over it is a floor of the equal-error one.
int pick_most_accurate_full(const RunRecord& recommended, const std::vector<RunRecord>& runs,
                            const std::vector<std::string>& quantities);

struct Baseline {
  std::string what;   // "reference", "full run at equal or better error", "cheapest full run"
  std::string label;  // the full run
  double wall_s = 0.0;
  double speedup = 0.0;  // baseline wall / recommended wall
};

// Baselines: the reference, the full run compared with (index, −1: none; at equal or better
// error, or when `as_accurate` is false the ladder's most accurate run, named so) and the
// cheapest completed full run of the ladder.
std::vector<Baseline> calc_baselines(const RunRecord& recommended, const RunRecord& reference,
                                     const std::vector<RunRecord>& runs, int compared_full, bool as_accurate = true);

// Where the error of `quantity` at a reduced setting comes from (each relative to the peak):
// the reference's own accuracy (its change when its tolerance is halved), the table (the same
// grid and interpolation integrated at the tightest tolerance), the integration (what the
// setting's integrator adds to that: |its error − the table's|), all measured on rows as
// accurate as the integrator's steps; and the output interpolation (what quintic-Hermite rows
// between steps, as a timed run writes them, add: their largest difference from those rows).
struct ErrorBudget {
  double reference = 0.0, table = 0.0, integration = 0.0, total = 0.0;
  double output_interpolation = 0.0;  // NaN when the run has no Hermite rows measured
  std::string table_run;  // empty when the ladder has no tight run at that grid
};
ErrorBudget calc_error_budget(const RunRecord& run, const std::vector<RunRecord>& runs,
                              double reference_change, const std::string& quantity,
                              double tightest_tolerance);

}  // namespace rdyn::validate
