// Forward dynamics of the full model with Simbody's error-controlled integrators; load
// switches (rate gates) located as events. This is rdyn's ground truth.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"
#include "models/timeseries.hpp"

namespace rdyn::engine {

struct ForwardOptions {
  double duration_s = 5.0;          // (0, ∞), finite [s]
  double output_interval_s = 0.01;  // > 0, at most kMaxOutputRows rows [s]
  double tolerance = 1e-9;  // integrator accuracy (relative), (0, 1]; constraints held to ≤ this too
  std::string integrator = "rkmerson";  // rkmerson | rk3 | cpodes
  // Budgets, so that no run hangs (NumericalError naming the time reached and the step size).
  // Each internal step is counted, so one output interval of microscopic steps is bounded too.
  // 5e6 steps: the shipped scenes take at most ~6e3 per simulated second at their tolerance
  // (measured: motor-startup 24162 steps for 4 s, thousand-cycles 2.8e5 for 210 s), so this is
  // ~800 simulated seconds of the hardest of them. A run whose recent mean step projects to
  // more than 100 budgets stops at once (see simulate_full).
  long max_steps = 5'000'000;  // integrator steps attempted, > 0
  double max_wall_s = 600.0;   // wall-clock time of the integration [s], > 0
  // The run checks its own energy balance: max|E − E0 − W| (models::energy_balance) must not
  // exceed energy_tolerance·scale + kEnergyFloor_J, scale = the largest |E|, kinetic energy or
  // |W| seen (|E| alone is ~0 when the potential's datum makes E ≡ 0). 1 %: a correct run at
  // the loosest tolerance the validation uses (CPodes at 1e-7 through the parallelogram's
  // singular positions) stays near 1e-4, a run that lost its energy is off by tens of percent.
  double energy_tolerance = 0.01;  // (0, ∞)
  // The independent coordinate's validity domain (a run leaving it stops with NumericalError).
  // Empty: simulate_full computes it (calc_independent_domain: a continuation walk of ~10 ms on
  // the bicycle), so callers that time repeated runs pass it in.
  std::optional<IndependentDomain> domain = std::nullopt;
  // The branch guard at every output sample (engine/branch_guard.hpp). Off only for timed
  // repeats of a run whose outputs were already checked with it on (validate's full-model
  // ladder): with one output at the end it walks the whole run's range of q once, ~0.1 s on the
  // bicycle's 5 s, which would be charged to Simbody's cost and inflate every speedup.
  bool branch_guard = true;
  // Configurations of rank loss crossed in the partitioned formulation (engine/
  // singular_passage.hpp). Off: Simbody's integrator steps through them itself, and the branch
  // guard stops a run that leaves its branch there — only to show what the passages are for
  // (tests, measurements); no command turns it off.
  bool singular_passages = true;
};

// Output rows (duration / interval + 1) a run may produce: 1e7 rows of ~8 doubles is ~0.6 GB.
inline constexpr long kMaxOutputRows = 10'000'000;
// Absolute floor of the energy-balance test [J]: a motion whose energies are all ~0 (at rest,
// no loads) has a residual of rounding size only.
inline constexpr double kEnergyFloor_J = 1e-12;

using models::RunStats;
using models::TimeSeries;

// Starts at the scene's initial q, q̇ (the rest of the state from the constraints).
// Throws EngineError for options out of range or a scene the engine refuses, and
// models::NumericalError when the integration fails on valid input: integrator error, step
// or wall-time budget exhausted, a non-finite value, an energy balance that does not close, or a
// switch of assembly branch (engine/branch_guard.hpp: checked at every output sample, ~0.2 ms
// each on the bicycle). A start at a singular configuration is a models::SceneError (`initial`).
// Through configurations where the loop Jacobian loses rank (domain.singular) the motion is
// integrated in the independent coordinate (engine/singular_passage.hpp); stats.singular_passages
// counts those windows.
TimeSeries simulate_full(const FullModel& model, const ForwardOptions& options);

}  // namespace rdyn::engine
