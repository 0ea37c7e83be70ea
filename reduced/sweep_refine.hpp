// Refinements of the extraction's grid visit (reduced/extract.cpp), each on the kinetostatic
// source at points between grid points: the switch angles of rate-gated loads (zeros of a
// joint's velocity ratio), where a point force's line passes through zero length, and the
// limits that replace a sample at a singular configuration. Internal to reduced/.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "reduced/kinetostatic_source.hpp"

namespace rdyn::reduced {

// The zero of joint j's velocity ratio inside one grid interval [a, b] (ra, rb of opposite
// signs), located on the source: a tight bracket around `est`, widened until the sign changes,
// then Brent's method (GSL) to 1e-13.
double refine_root(KinetostaticSource& src, int j, double a, double ra, double b, double rb, double est);

// The same zero by Newton's method on the ratio and its slope (sa, sb at a, b); empty when it
// does not converge in 8 evaluations (the caller then uses refine_root).
std::optional<double> newton_root(KinetostaticSource& src, int j, double a, double ra, double sa, double b, double rb,
                                  double sb);

// Zero of the quadratic through three samples (x0 < x1 < x2) inside [x1, x2], else the chord.
double quadratic_zero(double x0, double y0, double x1, double y1, double x2, double y2);

// Where point force f's points meet between grid points a < b, given dL/dq there (La < 0 < Lb);
// empty when they stay apart.
std::optional<double> find_point_force_meeting(KinetostaticSource& src, long f, double a, double La, double b,
                                               double Lb);

// The value a column takes at a singular grid point q_s (the loop Jacobian lost rank there, so
// the constraints do not determine the rates and a sample there is a least-squares value of no
// branch): the limit along the branch from both sides, by Richardson extrapolation of the
// symmetric means f̄(d) = ½[f(q_s − d) + f(q_s + d)] = f(q_s) + O(d²):
//   f(q_s) ≈ [4 f̄(δ/2) − f̄(δ)] / 3,  error O(δ⁴).
// The side samples carry the projection's residual (~1e-12) magnified by the conditioning
// twice (positions, then rates): measured on the parallelogram, a rate's error is ~1e-12/δ²
// (1.5e-6 at δ = 1e-3, 3e-8 at 1e-2), against the truncation's O(δ⁴); δ = 1e-2 balances them
// near 1e-8 of a column's size. A spline through the regular samples, the former patch, missed
// by the interpolation error: a parallelogram chain's gravity term 19.6187 for 19.62.
inline constexpr double kSingularLimitStep_rad = 1e-2;

// Replaces sample g at the singular grid point q_s by that limit (δ = kSingularLimitStep_rad, at
// most a quarter of the grid step); false, g unchanged, when a side sample is singular too or a
// limit is not finite. `pole_residues`, when given, gets per constraint force the residue a of a
// pole a/(q − q_s) that the side samples show in me1, me2 and Q_x (0: none; is_simple_pole).
// The extraction confirms a pole against the grid neighbours (extract.cpp, find_force_poles).
bool calc_singular_limit(KinetostaticSource& src, double q_s, double grid_step, bool conservative_loads,
                         GridSample& g, std::vector<std::array<double, 3>>* pole_residues = nullptr);

// Whether a column sampled at q_s − δ, q_s − δ/2, q_s + δ/2, q_s + δ (values m1, m2, p2, p1) has
// the shape of a simple pole at q_s, f ≈ a/(q − q_s) + regular. Some constraint forces have one
// at a singular configuration: the constraint actuator's own rates diverge there (an isosceles
// slider-crank folded flat: me1 ≈ 0.026/x kg), and the symmetric limit above is then the
// principal value, not a value of the branch. Test: the antisymmetric part ½[f(q_s + d) −
// f(q_s − d)] doubles when d halves, keeping its sign (a regular column's halves), and dominates
// the change of the symmetric part by 100×. Rounding noise can take that shape; the residue
// must then also be the one the grid neighbours show.
bool is_simple_pole(double m1, double m2, double p2, double p1);

}  // namespace rdyn::reduced
