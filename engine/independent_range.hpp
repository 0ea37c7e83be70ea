// The validity domain of the independent coordinate: declared in the scene
// (independent_range), a full turn of a revolute that turns fully, or found from the
// mechanism's dead points by continuation on the full model.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/full_model.hpp"

namespace rdyn::engine {

// A found range stops short of each dead point by this fraction of the distance between the
// two dead points: m1 grows without bound there (like 1/distance for a slider-crank driven
// from its slider: dθ/ds ∝ 1/√(s_dead − s)), so a table reaching the dead point cannot be
// interpolated. 1 %, with range tables ending at a dead point sampled kDeadPointRefinement
// (reduced/extract.hpp) times finer, so that the last grid interval is 0.28 of its distance to
// the dead point at a 10° grid: measured on slider-crank-slider released 1e-7 m inside the edge,
// reduced against full ≤ 2.4e-4 of the scale on the rod force and 6e-5 on q̇ (the 5 % margin
// this replaced, at 36 intervals: 3.3e-3 and 8.9e-4; docs/theory.md, "Range tables").
inline constexpr double kDeadPointMargin = 0.01;

// A configuration inside the domain where the loop Jacobian loses rank (a parallelogram lying
// flat): the full model passes it in the partitioned formulation (engine/singular_passage.hpp).
struct SingularPoint {
  double q = 0.0;           // the configuration of rank loss [rad or m]
  double half_width = 0.0;  // the window is q ± half_width [rad or m]
  // Within q ± limit_radius the rates are too poorly determined to be used (the conditioning is
  // below kLimitConditioning there): values are limits from outside it [rad or m].
  double limit_radius = 0.0;
  double conditioning = 0.0;  // the loop Jacobian's at q (below kSingularConditioning)
};

struct IndependentDomain {
  bool periodic = false;  // a revolute turning fully, no range declared: no edges
  double min = 0.0, max = 0.0;  // edges of the domain [rad or m] (not set when periodic)
  std::string min_edge, max_edge;  // "dead point" or "declared limit"
  // The dead points themselves, located to ~1e-10 by bisection [rad or m] (found ranges only).
  std::optional<double> dead_min, dead_max;
  bool revolute = true;
  // Not periodic, yet no range could be found (a prismatic coordinate meeting no dead point, or
  // only one): min = −∞, max = +∞ and this says why. The full model runs unbounded; a reduced
  // table needs a declared independent_range (extraction refuses with this message).
  std::string unbounded_reason;
  // Configurations of rank loss inside the domain (calc_singular_points), in walking order.
  std::vector<SingularPoint> singular;
};

// Declared range: returned as given after walking to both ends (EngineError when a dead point
// lies inside it). Otherwise walks the full model from the scene's
// initial q in both directions (continuation in moves of 10°, or 1/20 of the mechanism's size
// for a prismatic coordinate, refined to 1/50 of that when a projection fails) until the loops
// cannot close, then bisects to the dead point. A revolute that completes a turn is periodic.
// A prismatic coordinate that meets no dead point within 40 mechanism sizes, or only one,
// gets an unbounded domain (unbounded_reason). Throws EngineError when the initial q lies within
// the margin of a dead point, models::NumericalError when the walk exceeds its budget of moves.
IndependentDomain calc_independent_domain(const FullModel& model);

// calc_independent_domain without the scan for singular points (domain.singular stays empty):
// the walk alone, which decides periodic, the edges and the dead points. For callers that only
// ask whether the coordinate turns fully (calibration and sweeps, once per table): the scan
// samples the loop Jacobian's conditioning every kScanMove over the turn, ~20× the walk's cost
// on the bicycle (55 of 60 ms per sweep case over the rider's height, issue #28).
IndependentDomain calc_independent_domain_edges(const FullModel& model);

// Size of the mechanism [m]: the largest distance of any point (ground points, body points,
// centres of mass, joint locations) from its frame's origin, and the travel of prismatic joints (guesses; the independent one's initial q and declared range); at least 1 mm. Sets the
// continuation moves of a prismatic coordinate.
double calc_length_scale(const models::Scene& scene);

// The distance a found range keeps from each dead point, kDeadPointMargin of theirs [rad or m];
// 0 when the domain has no dead points (full turn, declared, unbounded).
double calc_dead_point_margin(const IndependentDomain& domain);

// Why the domain is what it is, one sentence for `rdyn inspect` (text and JSON): "full turn: …",
// "declared by the scene: …", "dead points found at … and …; the range stops … (1 % of their
// distance) short of each: […]", or the unbounded reason. `joint` is the independent joint.
std::string describe_domain(const IndependentDomain& domain, const std::string& joint);

// "q = 12.5°" or "q = 0.2345 m".
std::string format_coordinate(double q, bool revolute);

}  // namespace rdyn::engine
