// One steady cycle of the full model with every joint's coordinate output: what the validate
// and optimize reports animate (validate/report/cycle_animation.hpp). The cycle is re-run from
// an exact state of a longer run (the validation's reference) or from a steady point (an
// optimised strategy's), so the long run keeps its own outputs and only one cycle of frames is
// computed. The scene's loads do not depend on time (models/scene.hpp), so a run restarted from
// a state at t₀ is the same motion shifted by t₀.
#pragma once

#include "models/scene.hpp"
#include "models/timeseries.hpp"

namespace rdyn::validate {

// Output intervals of the cycle (61 frames: 6° apart at a steady cadence), enough for a smooth
// animation at a small cost (one period of Simbody with 61 outputs).
inline constexpr int kCycleIntervals = 60;

// Where a cycle starts and how long it lasts.
struct CycleStart {
  double t_s = 0.0;         // its start in the run it was taken from [s]
  double q = 0.0;           // the independent coordinate there [rad or m]
  double qdot = 0.0;        // its rate there [rad/s or m/s]
  double duration_s = 0.0;  // one cycle [s], > 0
  bool revolution = true;   // a whole revolution of the independent coordinate (else a stretch of time)
};

// The last whole revolution of `run` (crossings of q(0) ± 2πk, analysis/confirm_full.hpp's
// calc_revolution_times in the direction q moved): it starts at the first output row at or
// after the second-last crossing (a state of the run, exactly) and lasts as long as the time
// between the last two crossings. A run with fewer than two crossings (a rocker, a slider, a
// transient) gives its last `fallback_s` (the whole run when it is shorter; revolution false). Throws
// std::invalid_argument for a run with fewer than two rows or a fallback that is not > 0.
CycleStart calc_last_cycle(const models::TimeSeries& run, double fallback_s);

// The full model (Simbody, the scene's tolerance) from (c.q, c.qdot) over c.duration_s, output
// every c.duration_s / intervals with every joint's coordinate (q_<joint>) and the scene's
// requested outputs; times shifted by c.t_s. Throws as engine::simulate_full.
models::TimeSeries simulate_cycle(const models::Scene& scene, const CycleStart& c, int intervals = kCycleIntervals);

}  // namespace rdyn::validate
