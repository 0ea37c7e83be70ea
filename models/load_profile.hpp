// A periodic profile of a joint angle that shapes a drive load: τ(θ) per unit amplitude, so
// that a joint torque with a profile applies value·τ(θ_of) (the scene's `torque_Nm`/`force_N`
// stays an amplitude a calibration can scale). Plain data, no Simbody.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace rdyn::models {

namespace limits {
inline constexpr std::size_t kMaxProfileHarmonics = 64;  // a_k, b_k: k = 1..64
inline constexpr std::size_t kMinProfileRows = 3, kMaxProfileRows = 720;  // table_deg rows (0.5° apart)
inline constexpr double kMinProfileSpacing_deg = 0.01;  // consecutive table angles
}  // namespace limits

// τ(θ) of the angle θ [rad] of revolute joint `of` (the joint's coordinate q, as the scene
// defines it: child rotation relative to the parent minus offset_deg), 2π-periodic.
//  Fourier:  τ(θ) = a0 + Σ_k a_k cos kθ + b_k sin kθ           (table_theta_rad empty)
//  table:    periodic cubic spline through (θ_i, τ_i), θ_0 < θ_1 < … < θ_0 + 2π; C², no
//            overshoot control (like GSL's cspline_periodic).
struct LoadProfile {
  std::string of;  // revolute joint whose angle the profile reads
  double a0 = 0.0;
  std::vector<double> a, b;  // cos and sin coefficients of harmonics 1, 2, … (either may be shorter)
  std::vector<double> table_theta_rad, table_value;  // rows, θ increasing within one turn [rad]
  std::vector<double> table_d2;  // spline second derivatives at the rows (make_table_profile)
  bool is_table() const { return !table_theta_rad.empty(); }
};

// A table profile with its spline's second derivatives (solved once: the model is immutable).
// Rows must already be checked (check_profile_rows); the cyclic tridiagonal system of the
// periodic spline is diagonally dominant, so it always has a solution.
LoadProfile make_table_profile(std::string of, std::vector<double> theta_rad, std::vector<double> value);

// τ(θ) per unit amplitude; θ any finite angle [rad].
double calc_profile(const LoadProfile& p, double theta);

// A bound on |τ(θ)| over a turn: |a0| + Σ |a_k| + |b_k| for Fourier; for a table, the largest
// |τ_i| plus the spline's possible overshoot (bounded through its second derivatives).
double calc_profile_bound(const LoadProfile& p);

}  // namespace rdyn::models
