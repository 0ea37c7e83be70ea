// Time integration of the reduced model; same outputs as the full model.
#pragma once

#include <string>

#include "models/timeseries.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {

struct ReducedOptions {
  double duration_s = 5.0;
  double output_interval_s = 0.01;
  double tolerance = 1e-10;              // adaptive: relative and absolute error per step
  std::string integrator = "rk8pd";      // rk8pd | rkf45 | rkck (GSL odeiv2) | rk4-fixed
  double fixed_step_s = 1e-3;            // rk4-fixed only
};

// Integrates from (q0, q̇0). Load switches are located as events (the state where the
// switching function crosses zero, to ~1e-13 s) and the integration restarts there.
// Throws TableError on an unknown integrator or a non-finite state.
models::TimeSeries simulate_reduced(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt);

}  // namespace rdyn::reduced
