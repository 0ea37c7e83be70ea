// The scene's own time scale, and the settings of `rdyn validate` derived from it, so a 30 ms
// transient and a 210 s run of a thousand cycles get ladders fitted to them.
#pragma once

#include <string>
#include <vector>

#include "models/timeseries.hpp"

namespace rdyn::validate {

struct TimeScale {
  double period_s = 0.0;    // time for one revolution at the reference's peak speed, else the run
  double duration_s = 0.0;  // the run as simulated
  std::string how;          // plain words for the report
};

// Fewest steps any fixed-step run of the ladder takes over the run: fewer do not resolve
// the motion (the 30 ms transient got 1-step rows that "diverged").
constexpr double kMinFixedSteps = 100;
// Below this duration a cost is reported for the run as simulated only: a per-second figure
// would extrapolate beyond what was simulated.
constexpr double kMinDurationPerSecond_s = 1.0;

// Rotating coordinates: 2π / max|q̇| of the reference (one revolution at its peak speed),
// capped at the duration; otherwise (or when the reference barely moves) the duration.
TimeScale calc_time_scale(const models::TimeSeries& reference, bool rotating);

// Fixed steps of the real-time stepper: period/1000 … period/25 (1–40 ms for a 1 s cycle),
// each capped so the run takes at least kMinFixedSteps; duplicates removed, ascending.
// `quick`: the period/200 step only.
std::vector<double> calc_fixed_step_ladder(const TimeScale& ts, bool quick);

// Fixed steps of a peer engine's ladder (MuJoCo): period/10000 … period/300 (0.1–3 ms for a 1 s
// cycle: MuJoCo's soft loop closures need steps ~10× finer than the reduced model's RK4 for the
// same constraint-force error), each capped so the run takes at least kMinFixedSteps; ascending.
// `quick`: the period/1000 step only.
std::vector<double> calc_peer_step_ladder(const TimeScale& ts, bool quick);

// Whether a cost per simulated second is a measurement (the run lasted at least that long).
inline bool per_second_is_measured(double duration_s) {
  return duration_s >= kMinDurationPerSecond_s;
}

}  // namespace rdyn::validate
