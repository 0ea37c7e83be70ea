// The work per revolution of every non-conservative load at the calibration's constant target
// rate (validate/analysis/calibrate.cpp: the energy balance's first guess and its refusals).
#pragma once

#include <vector>

#include "reduced/reduced_model.hpp"
#include "validate/analysis/calibration_load.hpp"

namespace rdyn::validate {

// The work per revolution of every non-conservative load at the constant target rate, with the
// selected loads at unit value (±1: set_load(m, sel, 1) first). Both parts are linear in the
// load values: a torque does T·∫ r [gate] dq, a point force T·∫ τ (−dL/dq) [gate] dq, a motor
// s·∫ (1 − r q̇/ω0) r dq, a brake ∫ T_b(w q̇) w dq (springs and gravity do none over a turn).
struct RevolutionWork {
  double unit = 0.0;            // the selected loads' work per unit value [J per N·m or N]
  double other = 0.0;           // every other load's [J]
  double scale = 0.0;           // Σ|r| dq of the selected loads, for the round-off test of `unit`
  double other_scale = 0.0;     // Σ|work| of the others, for the round-off test of `other`
  double max_motor_rate = 0.0;  // a selected motor's largest joint rate over its no-load speed
  double brakes = 0.0;          // the resistances' alone [J]
  // Each other load's [J], to name them when they already balance the resistances.
  std::vector<double> torque, force, motor;
};

// Midpoint sums over n = 3600 points of one turn from q_start at q̇ = 2π·cadence_hz, the selected
// loads at unit value (set_load(m, sel, 1) first).
RevolutionWork calc_revolution_work(const reduced::ReducedModel& m, const Selection& sel, double q_start,
                                    double cadence_hz);

}  // namespace rdyn::validate
