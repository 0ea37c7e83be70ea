// What `rdyn validate` runs: the full-model tolerance ladder, the reduced ladder (grid ×
// interpolation × integrator) and how each run is timed — one plain record, decided in one
// place from the options and the scene's time scale.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "validate/harness/time_scale.hpp"
#include "validate/harness/timing.hpp"

namespace rdyn::validate {

struct ReducedVariant {
  std::string interpolation;
  bool energy_consistent = false;
};

struct LadderPlan {
  std::vector<std::pair<std::string, double>> full;  // (integrator, tolerance)
  std::vector<double> grids_deg;                     // coarse to fine
  std::vector<ReducedVariant> variants;
  std::vector<double> rk8pd_tolerances;  // ascending accuracy; the last is the tightest
  bool rkck = false;                     // one rkck run at 1e-8 per variant
  std::vector<double> fixed_steps_s;     // rk4-fixed, from the time scale
  std::vector<double> peer_steps_s;      // peer engines' fixed steps, from the time scale
  // Full-model runs are timed with one output at the end (fair baseline: the output grid does
  // not cap the step); their errors come from one untimed run on the output grid.
  bool time_full_without_outputs = true;
  // The same rule for the reduced model and the peer engines (issue #11 item 6: one rule for
  // every engine in a matched-error ratio): timed with one output at the end of the run, errors
  // from the same settings on the output grid. Their steps do not depend on the outputs (the
  // reduced model's rows are interpolated or extra single steps; a peer's fixed step divides the
  // output interval), so the timed and the compared runs take the same steps.
  bool time_reduced_without_outputs = true;
  bool time_peers_without_outputs = true;
  RepeatPolicy full_repeats, reduced_repeats, peer_repeats;
  int extraction_repeats_10deg = 1;  // median of this many for the 10° table
  double tightest_tolerance() const { return rk8pd_tolerances.back(); }
  long reduced_runs() const;  // runs of the reduced ladder
};

// `quick`: short ladders and single repeats (suites, smoke runs).
LadderPlan plan_ladders(const TimeScale& scale, bool quick);

// The plan with `grid_deg` among its grids (kept coarse to fine), when it is not already: the
// scene's default grid (ValidationResult::default_grid_deg) is always run, so a scene that 10°
// does not resolve is judged and recommended on the grid the commands take (2.5° for a five-bar
// geared 6:1, not in the quick ladder's 30, 10, 5).
LadderPlan with_grid(LadderPlan plan, double grid_deg);

}  // namespace rdyn::validate
