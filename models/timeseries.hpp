// A simulated motion, sampled at output times: the common result of the full and the
// reduced model (written as timeseries.csv). Plain data.
#pragma once

#include <algorithm>
#include <cmath>
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
  long singular_passages = 0;  // windows of rank loss crossed in the partitioned formulation (full model)
  // Output rows within ~1e-4 rad of rank loss, where the rates (and the constraint forces) are not
  // determined: their values are the limit stencil's interpolation (full model).
  long interpolated_rows = 0;
};

struct TimeSeries {
  std::vector<std::string> force_names;     // one per requested constraint force
  std::vector<double> t, q, qdot, qddot;    // [s], [rad or m], [/s], [/s²]
  std::vector<double> energy;               // kinetic + potential [J]
  std::vector<double> work;                 // cumulative work of non-conservative loads [J]
  std::vector<std::vector<double>> forces;  // forces[k][i]: force k at sample i [N]
  std::vector<std::uint32_t> gates;         // bit g set: rate-gated load g on at sample i
  // Every requested joint's motion and reaction and the shaking load (outputs.joints, reactions,
  // shaking; names and units: reduced/joint_outputs.hpp), written after the forces.
  std::vector<std::string> column_names;
  std::vector<std::vector<double>> columns;  // columns[c][i]: column c at sample i
  RunStats stats;
};

// The columns of timeseries.csv in order (validate/report/timeseries_csv.hpp writes them):
// t, q, qdot, qddot, energy, work, F_<name> per constraint force, then the joint outputs.
inline std::vector<std::string> timeseries_column_names(const std::vector<std::string>& force_names,
                                                        const std::vector<std::string>& column_names) {
  std::vector<std::string> n{"t", "q", "qdot", "qddot", "energy", "work"};
  for (const auto& f : force_names) n.push_back("F_" + f);
  n.insert(n.end(), column_names.begin(), column_names.end());
  return n;
}
inline std::vector<std::string> timeseries_column_names(const TimeSeries& ts) {
  return timeseries_column_names(ts.force_names, ts.column_names);
}
// Column k of that list (k < its size).
inline const std::vector<double>& timeseries_column(const TimeSeries& ts, size_t k) {
  const std::vector<double>* fixed[] = {&ts.t, &ts.q, &ts.qdot, &ts.qddot, &ts.energy, &ts.work};
  if (k < 6) return *fixed[k];
  return k - 6 < ts.forces.size() ? ts.forces[k - 6] : ts.columns[k - 6 - ts.forces.size()];
}

// The output grid of a run: rows at t = i·interval for i = 0…n−1 and a last row at t =
// duration, also when the interval does not divide it (1 s at 0.3 s: 0, 0.3, 0.6, 0.9, 1), so
// the final state is always written. calc_output_rows is n + 1 without the t = 0 row, i.e. the
// rows after the start; a quotient within 1e-9 of a whole number counts as whole (1 s / 0.1 s
// is 10.000000000000002), so no sliver row appears next to the last one.
inline long calc_output_rows(double duration_s, double interval_s) {
  return static_cast<long>(std::ceil(duration_s / interval_s - 1e-9));
}
// Time of row i (1…rows) of that grid; the last is exactly the duration.
inline double calc_output_time(long i, long rows, double duration_s, double interval_s) {
  return i >= rows ? duration_s : std::min(duration_s, static_cast<double>(i) * interval_s);
}

// Energy balance of a simulated motion: E(t) − E(0) = W(t), the work of the non-conservative
// loads integrated next to the motion, so the residual max|E − E0 − W| measures what the
// integration lost or invented [J]; the largest |E| seen is its natural scale [J].
struct EnergyBalance {
  double max_residual_J = 0.0;
  double energy_scale_J = 0.0;
  double worst_time_s = 0.0;  // where the residual is largest [s]
};
inline EnergyBalance energy_balance(const TimeSeries& ts) {
  EnergyBalance b;
  for (size_t i = 0; i < ts.t.size(); ++i) {
    const double r = std::abs(ts.energy[i] - ts.energy[0] - ts.work[i]);
    if (r > b.max_residual_J) {
      b.max_residual_J = r;
      b.worst_time_s = ts.t[i];
    }
    b.energy_scale_J = std::max(b.energy_scale_J, std::abs(ts.energy[i]));
  }
  return b;
}

}  // namespace rdyn::models
