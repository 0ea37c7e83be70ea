// Adaptive integration of the reduced equation y = (q, q̇, W) with GSL's odeiv2 steppers, load
// switches located as events; the limits of the reduced integrators' options; and the pieces the
// fixed-step path of simulate_reduced shares (Hermite rows inside a step, the domain's edge).
#pragma once

#include <cmath>
#include <memory>
#include <string>

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

// An adaptive method's name: rk8pd, rkf45 or rkck.
bool is_adaptive_method(const std::string& name);

// Quintic Hermite through (q, q̇, q̈) at both ends of a step, at fraction s of it; cubic Hermite
// for W through (W, P).
void calc_hermite(const AdaptiveIntegrator::Point& a, const AdaptiveIntegrator::Point& b, double s, double& q,
                  double& qdot, double& work);

// A step from q0 to q1 (q monotone) that passes a whole window of gate g — two or more of its
// switch angles (Gate::roots, every turn's copy on a periodic table) strictly between q0 and q1,
// so its switching function may have the same sign at both ends: the fraction of the step at which
// q reaches the middle of the first window in the direction of motion; 1 when it passes fewer
// than two (or the gate's angles are not known).
double calc_gate_window_fraction(const ReducedModel& m, int g, double q0, double q1);

// The edge of a range table's validity domain that q has crossed.
double domain_edge(const ReducedModel& m, double q);

// A run that reaches the edge of a range table stops (NumericalError, exit 1) naming the edge
// and the time.
[[noreturn]] void throw_left_domain(const ReducedModel& m, double edge, double t);

}  // namespace rdyn::reduced
