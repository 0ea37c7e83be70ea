// Time integration of the reduced model; same outputs as the full model.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "models/timeseries.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {

struct ReducedOptions {
  double duration_s = 5.0;
  double output_interval_s = 0.01;
  double tolerance = 1e-8;           // adaptive: relative and absolute error per step
  std::string integrator = "rk8pd";  // rk8pd | rkf45 | rkck (GSL odeiv2) | rk4-fixed
  double fixed_step_s = 1e-3;        // rk4-fixed only
};

// Adaptive GSL odeiv2 integration of y = (q, q̇, W) with load switches located as events:
// after each step the switching functions are checked; a sign change is located by the
// Illinois (regula falsi) method on single steps from the start of the step (to ~1e-13 s),
// the step is cut there and the gate flips before the next step.
class AdaptiveIntegrator {
 public:
  AdaptiveIntegrator(const ReducedModel& m, double tolerance, const std::string& method = "rk8pd");
  ~AdaptiveIntegrator();
  // Sets the state and the gates (from rest: as init_gates).
  void reset(double t, double q, double qdot, double work = 0.0);
  // Advances to t_end, or until q reaches q_stop (if finite), located like an event.
  // Returns true when it stopped at q_stop. Throws TableError on a non-finite state or when
  // q leaves a non-periodic table.
  bool advance(double t_end, double q_stop = NAN);
  // One accepted step toward t_end (cut at an event or at q_stop). Returns true when it
  // stopped at q_stop. After it, step_start()/state() bound the step and the gates are still
  // those used inside it (a located switch is applied at the start of the next step).
  bool step(double t_end, double q_stop = NAN);
  struct Point {
    double t, q, qdot, qddot, work, power;
  };
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

// Integrates from (q0, q̇0) and samples every output interval.
models::TimeSeries simulate_reduced(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt);

}  // namespace rdyn::reduced
