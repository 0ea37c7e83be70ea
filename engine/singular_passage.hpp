// The full model through configurations where the loop Jacobian loses rank (a parallelogram
// lying flat, a four-bar folding onto its ground line): a change of formulation in a window
// around each such configuration (docs/theory.md, "Singular passages").
//
// Why: Simbody integrates the mechanism in all its coordinates and projects them onto the
// constraints; at rank loss the projection is singular, the branches cross, and its integrators
// either stop ("unable to advance time") or leave on the other branch with the energy conserved
// (a parallelogram chain's crank folding about its pivot). Inside the window the motion is
// integrated in the independent coordinate alone — Eksergian's equation m1 q̈ + m2 q̇² = F* — with
// m1 and the right-hand side taken at every evaluation from two inverse-dynamics calls of the
// same Simbody model (q̈ = 0 and q̈ = 1, every load applied) on the branch followed by
// continuation: Wehage–Haug coordinate partitioning with the independent coordinate as the
// independent set, which stays determined along the branch where the full Jacobian does not.
// Plain records; no Simbody type.
#pragma once

#include <functional>
#include <vector>

#include "engine/branch_guard.hpp"
#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"

namespace rdyn::engine {

// Conditioning (engine/kinetostatic.hpp, calc_loop_conditioning) below which Simbody's
// coordinate projection is left for the partitioned formulation: a window's edges are where it
// climbs back above this. 0.02: a parallelogram chain (κ ≈ 0.3 × distance in rad) gets
// windows of ±0.06–0.08 rad; constraint errors are amplified by 1/κ ≤ 50 outside them, so
// Simbody's 1e-10 constraint tolerance stays below 1e-8 in the coordinates. Regular mechanisms
// never come near it (the bicycle 0.06, the hard high-saddle 0.0075 at its tightest without
// rank loss: below 0.02 but not singular, so no window).
inline constexpr double kPassageConditioning = 0.02;
// Scan of the domain for rank loss: moves of at most this [rad, or × the mechanism's size for a
// prismatic coordinate]; a local minimum of the conditioning below kScanCandidate is refined by
// golden-section search and kept when it reaches kSingularConditioning (a true rank loss
// passes through 0 linearly, so the search brings it to ~1e-9).
inline constexpr double kScanMove = 0.02;
inline constexpr double kScanCandidate = 0.05;
// A window is at most this wide on each side [rad, or × the mechanism's size].
inline constexpr double kMaxPassageHalfWidth = 0.3;
// Near rank loss the branch rates carry the loop residual magnified by 1/κ² (m2 by 1/κ³,
// branch_rates.hpp). Where κ < kLimitConditioning (|q − q*| < limit_radius) a value is the
// degree-5 interpolation of its values at q* ± r, ± 2r, ± 3r (r = limit_radius): error
// ~ f⁽⁶⁾ Π(q − xᵢ)/6! < 2e-3 f⁽⁶⁾ r⁶. Measured on parallelogram chains against the exact q̈:
// direct evaluations at κ ≥ 2e-3 within 1e-12 (1 loop) and 6e-10 (10 loops) of it; a
// two-sided Richardson limit over 4r was 5e-4 off where r = 0.03 rad (10 loops).
inline constexpr double kLimitConditioning = 2e-3;

// The domain's configurations of rank loss (between its edges, or over one turn from the
// initial q when periodic), found by continuation along the starting branch. Empty for a
// mechanism without loops or whose Jacobian keeps its rank (every shipped mechanism but the
// parallelogram chains). Throws EngineError when the continuation cannot proceed.
std::vector<SingularPoint> calc_singular_points(const FullModel& model, const IndependentDomain& domain);

// Index of a window the motion touches while q moves from a to b (a step), or −1. Periodic
// domains compare modulo a turn.
int find_window(const std::vector<SingularPoint>& points, bool periodic, double a, double b);
// Whether q lies outside every window.
bool outside_windows(const std::vector<SingularPoint>& points, bool periodic, double q);

// Free acceleration and the power of the non-conservative loads at (q, q̇) on the branch the
// guard's workspace follows (follow_branch first, so it may start anywhere along it), by
// virtual power along the branch rates r: m1 q̈ + m2 q̇² = F* with m1 = rᵀMr, m2 = rᵀ(Mb + c) and
// F* = rᵀf(q, r q̇) from Simbody's mass matrix, bias and applied forces (every load on); near
// rank loss, the interpolation of the stencil's values.
struct FreeMotion {
  double qddot = 0.0;  // [rad/s² or m/s²]
  double power = 0.0;  // of the non-conservative loads [W]
};
// The nodes and weights of a value at q from outside the limit radius (empty: q is outside
// every limit radius, take the value at q itself).
struct LimitStencil {
  std::vector<double> x, w;
};
LimitStencil limit_stencil_at(const std::vector<SingularPoint>& points, bool periodic, double q);
FreeMotion calc_free_motion(const FullModel& model, BranchGuard& branch, double q, double qdot,
                            const LimitStencil& stencil);

// Puts the guard's workspace at (q, q̇, q̈) on its branch, every load applied, the independent
// coordinate prescribed, realized to Acceleration (a passage's output row is recorded from it;
// with q̈ the free acceleration the drive is zero). Returns the loop Jacobian's conditioning
// there (below kSingularConditioning the multipliers are not determined).
double set_passage_state(const FullModel& model, BranchGuard& branch, double q, double qdot, double qddot);

// The state of the partitioned integration.
struct PassagePoint {
  double t = 0.0, q = 0.0, qdot = 0.0, work = 0.0;  // [s], [rad or m], [/s], [J]
};

struct PassageOptions {
  double tolerance = 1e-9;  // local error per step, relative to max(|y|, 1)
  double t_end = 0.0;       // the run's duration [s]
  long max_steps = 0;       // steps this passage may take (the run's remaining budget)
  double max_wall_s = 0.0;  // wall-clock time it may take (the run's remaining budget) [s]
};

// Integrates from `start` (Dormand–Prince 5(4), error-controlled on q and q̇) until q has been
// inside a window and is outside every window again (or turned back before entering), or t_end. Every output time it crosses —
// next_output() gives the next one, +∞ when none is left — is landed on exactly and handed to
// on_output (which may throw). Returns the end point; `steps` counts the accepted steps.
// Throws models::NumericalError when the step budget runs out or a value is not finite.
PassagePoint integrate_passage(const FullModel& model, BranchGuard& branch, const std::vector<SingularPoint>& points,
                               bool periodic, const PassagePoint& start, const PassageOptions& options,
                               const std::function<double()>& next_output,
                               const std::function<void(const PassagePoint&)>& on_output, long& steps);

}  // namespace rdyn::engine
