// The operating point of a calibration in one Newton iteration on the first integral
// (docs/theory.md §6a, issue #11 item 4).
//
// Unknowns: u = q̇²/2 at the section, the load value T and, in power mode, the resistance
// coefficient c, all in logarithms (each is positive; the residuals are then relative). The
// residuals of one pass of the first integral from u (reduced::CyclePasses):
//   periodicity  ln(Φ(u)/u)          (the steady cycle: u returns to itself),
//   cadence      ln(F·t_cycle)        (the mean cadence is F),
//   power        ln(P_diss/P)         (the resistance dissipates P; power mode only).
// The Jacobian is taken by forward differences once and then updated by Broyden's rule, with
// step halving where a step stalls a pass or does not reduce the residual. The nested route
// — a root search over T, each evaluation a fixed-point search over u, inside a secant over
// c — stays the fallback and the cross-check (validate/analysis/calibrate.cpp).
#pragma once

#include <cmath>
#include <functional>
#include <optional>

#include "reduced/reduced_model.hpp"

namespace rdyn::validate {

struct OperatingPointTargets {
  double q_section = 0.0;   // section of the cycle [rad]
  double qdot_guess = 0.0;  // first guess of q̇ at the section [rad/s], non-zero: its sign is the direction
  double cadence_hz = 0.0;  // mean cadence F = 1 / period, > 0
  double power_w = NAN;     // P > 0, or NaN: the coefficient is not an unknown
  double tolerance = 1e-10;  // of the first integral's steps
  int max_passes = 30;       // bound on the passes (Newton, differences, halvings)
};

struct OperatingPoint {
  double load = 0.0;         // T
  double coefficient = NAN;  // c (NaN without a power target)
  double qdot_section = 0.0;
};

// `apply(T, c)` writes the load value and (power mode) the coefficient into `m`, which the
// passes read. Returns nothing when the iteration does not converge within max_passes (a
// stall, a singular Jacobian, a residual that stops falling): callers use the nested route.
// Converged: every residual below 1e-12 (periodicity), 1e-11 (cadence) and 1e-10 (power).
// `passes` is increased by the passes made, converged or not.
std::optional<OperatingPoint> solve_operating_point(const reduced::ReducedModel& m, const OperatingPointTargets& t,
                                                    double load_guess, double coefficient_guess,
                                                    const std::function<void(double, double)>& apply, int& passes);

}  // namespace rdyn::validate
