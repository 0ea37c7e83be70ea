// Confirmation on the full model of an operating point found on the reduced model (calibrate,
// optimize): the scene with its loads at the chosen values and its initial state on the reduced
// steady cycle, simulated with Simbody (engine::simulate_full), and measured — mean cadence,
// speed fluctuation, peak of one constraint force. Two measures: a window after a settling time
// (optimize: confirm_full), and whole revolutions once the run is steady (calibrate:
// confirm_full_steady, which runs as long as it takes, up to a cap).
#pragma once

#include <vector>

#include "models/scene.hpp"
#include "models/timeseries.hpp"

namespace rdyn::validate {

// Acceptance of a full-model confirmation: the mean cadence within 1 % of the target (issue
// #13: "holds 1 Hz within 1 %"). The reduced table's own error (≈ 1e-5 of the speed at 10°,
// docs/theory.md) and the window's quasi-steady drift keep a genuine operating point within 1e-4.
inline constexpr double kFullCadenceTolerance = 1e-2;

struct FullConfirmOptions {
  double duration_s = 6.0;          // simulated time from the steady point [s], > 0
  double skip_s = 1.0;              // the window starts at the first output row at or after this [s]
  int force = 0;                    // constraint force (outputs.constraint_forces index) whose peak is measured
  double output_interval_s = 0.002; // rows 2 ms apart: the crossings are interpolated linearly between them
  double tolerance = 1e-9;          // Simbody's accuracy: far below the 1e-4 the confirmation resolves
};

// The steady window's measures (NaN where the window does not give them).
struct FullConfirmation {
  // (q_last − q_first) / (2π (t_last − t_first)) over the window's rows [rev/s]: needs no whole
  // revolution, includes the last partial one.
  double mean_rate_hz = NAN;
  // Whole revolutions n from the window's start divided by the time they took, the end time
  // interpolated linearly between rows where q reaches q_first + 2πn [rev/s]; NaN without one.
  double cadence_hz = NAN;
  double speed_fluctuation = NAN;   // (max − min)/mean of q̇ over the window's rows
  double peak_force_N = NAN;        // max |F| of the chosen force over the window's rows (NaN: no such force)
  std::vector<double> force_1deg;   // that force over the last whole revolution at 0°, 1°, … 359° of q
};

// Samples (q, F) of one revolution resampled at 0°, 1°, … 359° of q mod 2π (linear between the
// samples, across the 360° wrap); 360 NaN when there are none.
std::vector<double> calc_by_angle(std::vector<std::pair<double, double>> pts);

// The measures of `ts` over its rows from `skip_s` on (a window with fewer than three rows gives NaN).
FullConfirmation calc_steady_window(const models::TimeSeries& ts, double skip_s, int force);

// `scene` (loads and initial state already set) simulated on the full model for
// opt.duration_s and measured from opt.skip_s. Throws as engine::simulate_full: EngineError for a
// scene the engine refuses, models::NumericalError when the integration fails.
FullConfirmation confirm_full(const models::Scene& scene, const FullConfirmOptions& opt);

// Times [s] at which q first reaches q(t₀) + 2πk·sign(direction), k = 1, 2, … (the start of the
// series is revolution 0). Between output rows q is the cubic Hermite interpolant through (q, q̇)
// at both rows (error ∝ h⁴ q⁗, against h² q̈ for a straight line), its crossing found by
// bisection. A series that turns back keeps the first crossing of each level.
std::vector<double> calc_revolution_times(const models::TimeSeries& ts, double direction);

// Measures over whole revolutions of the independent coordinate, m at a time: with n whole
// revolutions from the series' start (crossing times t_1 … t_n, t_0 its first row),
//   cadence_hz          = m / (t_n − t_{n−m})          the last m revolutions [rev/s],
//   previous_cadence_hz = m / (t_{n−m} − t_{n−2m})     the m before them (NaN when n < 2m).
// Fluctuation and peak force over the rows of the last m revolutions.
struct RevolutionMeasures {
  int revolutions = 0;               // n
  double cadence_hz = NAN;           // NaN when n < m
  double previous_cadence_hz = NAN;
  double speed_fluctuation = NAN;    // (max − min)/mean of q̇·sign over those rows
  double peak_force_N = NAN;         // max |F| of the chosen force over those rows (NaN: no such force)
};
RevolutionMeasures calc_revolution_measures(const models::TimeSeries& ts, double direction, int m, int force);

struct SteadyConfirmOptions {
  // The reduced steady cycle's cadence [rev/s], > 0: the first run lasts 2m + 1 of its periods
  // (2 % more, so that a full model a little slower still completes 2m revolutions).
  double cadence_hz = 0.0;
  int revolutions = 3;  // m: the cadence is the mean over the last m whole revolutions, ≥ 1
  // Steady: |cadence − previous cadence| ≤ this × cadence. 1e-4, a hundredth of the 1 % the
  // confirmation accepts; a genuine steady cycle repeats to the interpolation error (~1e-8).
  double steady_tolerance = 1e-4;
  // Cap on the simulated time [s]: a run that is not steady is repeated from the start at twice
  // its length, up to this; steady = false when even that run is not steady.
  double max_duration_s = 120.0;
  int force = 0;                     // constraint force whose peak is measured
  double output_interval_s = 0.002;  // rows 2 ms apart: crossings interpolated between them
  double tolerance = 1e-9;           // Simbody's accuracy
};

struct SteadyConfirmation {
  RevolutionMeasures measures;  // of the last (longest) run
  bool steady = false;
  double duration_s = 0.0;      // simulated time of the last run [s]
  int runs = 0;                 // runs made (each from the scene's initial state)
};

// `scene` (loads and its one initial state, q and q̇ on the reduced steady cycle, already set)
// simulated on the full model from its initial state until the last m whole revolutions' mean
// cadence agrees with the m before them to opt.steady_tolerance, or the cap is reached. Every run
// starts from the same state, so the measured trajectory is the one an independent run of that
// length gives. Throws as engine::simulate_full.
SteadyConfirmation confirm_full_steady(const models::Scene& scene, const SteadyConfirmOptions& opt);

}  // namespace rdyn::validate
