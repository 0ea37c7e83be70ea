// A simulated motion, sampled at output times: the common result of the full and the
// reduced model (written as timeseries.csv). Plain data.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rdyn::models {

struct RunStats {
  long steps_taken = 0;
  long steps_attempted = 0;
  long events = 0;                    // load switches located (reduced model)
  double smallest_step_s = 0.0;       // smallest step size used [s] (0 when unknown)
  double max_constraint_error = 0.0;  // largest loop-closure violation seen [m] (full model)
  double wall_time_s = 0.0;
};

struct TimeSeries {
  std::vector<std::string> force_names;     // one per requested constraint force
  std::vector<double> t, q, qdot, qddot;    // [s], [rad or m], [/s], [/s²]
  std::vector<double> energy;               // kinetic + potential [J]
  std::vector<double> work;                 // cumulative work of non-conservative loads [J]
  std::vector<std::vector<double>> forces;  // forces[k][i]: force k at sample i [N]
  std::vector<std::uint32_t> gates;         // bit g set: rate-gated load g on at sample i
  RunStats stats;
};

}  // namespace rdyn::models
