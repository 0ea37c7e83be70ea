// Forward dynamics of the full model with Simbody's error-controlled integrators; load
// switches (rate gates) located as events. This is rdyn's ground truth.
#pragma once

#include <string>
#include <vector>

#include "engine/full_model.hpp"

namespace rdyn::engine {

struct ForwardOptions {
  double duration_s = 5.0;
  double output_interval_s = 0.01;
  double tolerance = 1e-9;  // integrator accuracy (relative); constraints held to ≤ this too
  std::string integrator = "rkmerson";  // rkmerson | rk3 | cpodes
};

struct ForwardStats {
  long steps_taken = 0;
  long steps_attempted = 0;
  double smallest_step_s = 0.0;  // smallest step size used [s] (0 when unknown)
  double max_constraint_error = 0.0;  // largest position-constraint violation seen [m]
  double wall_time_s = 0.0;
};

// Samples every output_interval_s from 0 to duration_s inclusive.
struct TimeSeries {
  std::vector<std::string> force_names;  // one per requested constraint force
  std::vector<double> t, q, qdot, qddot;  // [s], [rad or m], [/s], [/s²]
  std::vector<double> energy;             // kinetic + potential [J]
  std::vector<double> work;               // cumulative work of non-conservative loads [J]
  std::vector<std::vector<double>> forces;  // forces[k][i]: force k at sample i [N]
  ForwardStats stats;
};

// Starts at the scene's initial q, q̇ (the rest of the state from the constraints).
// Throws EngineError on failure.
TimeSeries simulate_full(const FullModel& model, const ForwardOptions& options);

}  // namespace rdyn::engine
