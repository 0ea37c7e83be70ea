// Time integration of the reduced model; same outputs as the full model.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "models/timeseries.hpp"
#include "reduced/adaptive_integrator.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {

struct ReducedOptions {
  double duration_s = 5.0;           // (0, ∞) [s], with duration / output interval ≤ kMaxOutputRows
  double output_interval_s = 0.01;   // (0, ∞) [s]
  double tolerance = 1e-8;           // adaptive: relative and absolute error per step, [1e-14, 1e-1]
  std::string integrator = "rk8pd";  // rk8pd | rkf45 | rkck (GSL odeiv2) | rk4-fixed
  double fixed_step_s = 1e-3;        // rk4-fixed only, [1e-7, 1] s, duration / step ≤ max_steps
  // Output rows between steps. false: quintic Hermite through the step's ends (free, but its
  // own error can exceed the integrator's: 9e-7 of the speed on the bicycle at tolerance
  // 1e-12); true: one single step of the run's own method from the step's start to the row's
  // time (accurate to the integrator's tolerance; one extra step per row, and the steps
  // themselves are unchanged). Validation compares true rows; timings use false.
  bool step_outputs = false;
  long max_steps = kDefaultMaxSteps;     // steps attempted (adaptive: accepted + rejected)
  double max_wall_s = kDefaultMaxWall_s; // wall-clock budget of the run [s]
};

// Throws TableError (naming the option and its valid range) when an option is out of range;
// simulate_reduced calls it first. Allocates nothing.
void check_reduced_options(const ReducedOptions& opt);

// Integrates from (q0, q̇0) and samples every output interval. Throws TableError on options out
// of range (check_reduced_options) or a non-finite start; NumericalError when the run fails
// (budget exceeded, divergence of the energy balance, a non-finite value in an output).
models::TimeSeries simulate_reduced(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt);

// A finished run checks its energy balance as the full model's does: max|E − E0 − W| must stay
// within `tolerance` of the energy scale — the largest |E|, |W| or range of E over the run (|E|
// alone is ~0 where the potential's datum makes E ≡ 0) — plus 1e-12 J. The divergence guard
// (above) only stops runs that blow up: a fixed-step run too coarse for its mechanism closes it
// worse than that and still ends (the hard light-flywheel at 0.2 s steps: 18.6 J of 22.2 J).
// 1 %: the light flywheel at 0.01 s steps is at 0.9 %, the bicycle at 0.02 s at 5e-5.
// Throws EnergyBalanceError (a models::NumericalError) naming the residual, where it is largest
// and `how` (the integrator and its step or tolerance).
class EnergyBalanceError : public models::NumericalError {
 public:
  using models::NumericalError::NumericalError;
};
void check_energy_balance(const models::TimeSeries& ts, double tolerance, const std::string& how);

}  // namespace rdyn::reduced
