// Forward dynamics of the full model with Simbody's error-controlled integrators; load
// switches (rate gates) located as events. This is rdyn's ground truth.
#pragma once

#include <string>
#include <vector>

#include "engine/full_model.hpp"
#include "models/timeseries.hpp"

namespace rdyn::engine {

struct ForwardOptions {
  double duration_s = 5.0;
  double output_interval_s = 0.01;
  double tolerance = 1e-9;  // integrator accuracy (relative); constraints held to ≤ this too
  std::string integrator = "rkmerson";  // rkmerson | rk3 | cpodes
};

using models::RunStats;
using models::TimeSeries;

// Starts at the scene's initial q, q̇ (the rest of the state from the constraints).
// Throws EngineError on failure.
TimeSeries simulate_full(const FullModel& model, const ForwardOptions& options);

}  // namespace rdyn::engine
