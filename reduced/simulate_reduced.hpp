// Time integration of the reduced model; same outputs as the full model.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "models/timeseries.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {

// Valid ranges of the options, checked before any work (TableError, exit 2, naming the range).
inline constexpr long kMaxOutputRows = 10000000;  // duration / output interval + 1
inline constexpr double kMinTolerance = 1e-14;    // a few ulps of q ~ 2π: tighter cannot be met
inline constexpr double kMaxTolerance = 1e-1;
inline constexpr double kMinFixedStep_s = 1e-7;
inline constexpr double kMaxFixedStep_s = 1.0;
// Default run budgets: a run that needs more fails with NumericalError (exit 1) naming the
// simulated time it reached. 10⁸ steps is ~2 min of the bicycle's rk8pd steps on one core.
inline constexpr long kDefaultMaxSteps = 100000000;
inline constexpr double kDefaultMaxWall_s = 600.0;

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

// Step and wall-time budget of one AdaptiveIntegrator (counted from its construction).
struct IntegratorLimits {
  long max_steps = kDefaultMaxSteps;
  double max_wall_s = kDefaultMaxWall_s;
};

// Adaptive GSL odeiv2 integration of y = (q, q̇, W) with load switches located as events:
// after each step the switching functions are checked; a sign change is located by the
// Illinois (regula falsi) method on single steps from the start of the step (to ~1e-13 s),
// the step is cut there and the gate flips before the next step.
class AdaptiveIntegrator {
 public:
  // Throws TableError on an unknown method or a tolerance outside [kMinTolerance, kMaxTolerance].
  AdaptiveIntegrator(const ReducedModel& m, double tolerance, const std::string& method = "rk8pd",
                     IntegratorLimits limits = {});
  ~AdaptiveIntegrator();
  // Sets the state and the gates (from rest: as init_gates).
  void reset(double t, double q, double qdot, double work = 0.0);
  // Advances to t_end, or until q reaches q_stop (if finite), located like an event.
  // Returns true when it stopped at q_stop. Throws NumericalError when GSL fails, on a
  // non-finite state, or past the step or wall-time budget; NumericalError ("left the validity domain at q = …") when q leaves a
  // non-periodic table.
  bool advance(double t_end, double q_stop = NAN);
  // One accepted step toward t_end (cut at an event or at q_stop). Returns true when it
  // stopped at q_stop. After it, step_start()/state() bound the step and the gates are still
  // those used inside it (a located switch is applied at the start of the next step).
  bool step(double t_end, double q_stop = NAN);
  struct Point {
    double t, q, qdot, qddot, work, power;
  };
  // State (q, q̇, W) at t in [step_start().t, step_end().t] by one single step of the method
  // from the step's start with the gates used inside the step: as accurate as the step.
  void calc_within_step(double t, double y[3]);
  const Point& step_start() const;
  const Point& step_end() const;
  const ReducedWorkspace& state() const;
  long steps() const;
  long rejected() const;  // steps refused by the error control
  long events() const;
  double smallest_step() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

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
// Throws models::NumericalError naming the residual, where it is largest and `how` (the
// integrator and its step or tolerance).
void check_energy_balance(const models::TimeSeries& ts, double tolerance, const std::string& how);

}  // namespace rdyn::reduced
