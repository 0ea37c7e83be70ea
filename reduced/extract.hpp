// Reduced parameters from kinetostatic calls of a full model (the paper's method).
#pragma once

#include <optional>
#include <vector>
#include <string>

#include "models/scene.hpp"
#include "reduced/kinetostatic_source.hpp"
#include "reduced/samples.hpp"

namespace rdyn::reduced {

enum class Method {
  Kinetostatic,  // (i) q̈ = 0, q̇ = ω: m2 = T/ω², me2 = F/ω²; (ii) q̇ = 0, q̈ = α: m1 = T/α, me1 = F/α
  PaperSweep,    // the same states reached by continuous prescribed laws sampled at the grid
  Integrated,    // m1 = m1(q_first) + ∫ 2 m2 dq (m2 from (i), one m1 from (ii))
  Direct,        // m1 = uᵀMu etc. from the mass matrix (engine only)
};
Method parse_method(const std::string& name);  // throws TableError
std::string method_name(Method m);

// Extraction grid [deg]: from 0.01° (36 000 points a turn: the finest grid, a few seconds of
// kinetostatic calls) to 90° (4 points, the fewest a periodic spline takes). The step must
// divide 360°.
inline constexpr double kMinGridDeg = 0.01;
inline constexpr double kMaxGridDeg = 90.0;

// Number of grid points a turn for a grid step [rad]; throws TableError naming the valid range
// when the step is not finite, outside [kMinGridDeg, kMaxGridDeg] or does not divide 360°.
// Allocates nothing: call it before any work that depends on the grid.
long check_grid_step(double step_rad);

// A range of the independent coordinate for a non-periodic table (periodic=0).
struct ExtractRange {
  double min = 0.0, max = 0.0;     // [rad or m], min < max
  std::string min_edge, max_edge;  // what ends it: "dead point" or "declared limit" (recorded in the table)
};

// A range table ending at a dead point gets this many times the intervals of one ending at
// declared limits. The range stops 1 % of the dead points' distance short of each
// (engine::kDeadPointMargin), where m1 still grows like 1/distance (docs/theory.md, "Range
// tables"); a uniform grid interpolates that to a given accuracy when its step is a fixed
// fraction of the distance to the dead point: 10× gives 360 intervals at a 10° grid, a last
// interval 0.28 of its distance to the dead point (the same ratio at every grid of the ladder).
inline constexpr long kDeadPointRefinement = 10;

// Intervals of a range table for a grid step [rad]: a revolute range gets the fewest equal
// intervals no longer than the step; a prismatic one as many intervals as the step makes over a
// turn (a 10° grid: 36 intervals over the stroke), so the grid ladders of `rdyn validate` apply
// to both; kDeadPointRefinement times that when an edge is a dead point (capped at
// kMaxTableRows points). At least 4 intervals (5 points, what every interpolation takes: GSL's
// Akima needs 5). Throws TableError when the span is not finite and positive, or the unrefined
// grid makes more than kMaxTableRows points.
long range_intervals(double span, double step_rad, bool revolute, bool ends_at_dead_point);

struct ExtractOptions {
  double step_rad = 10.0 * 3.14159265358979323846 / 180.0;  // grid step (revolute) [rad]
  Method method = Method::Kinetostatic;
  // A periodic sweep must close its turn (SweepNotClosed otherwise). Off: a sweep that changed
  // branch on the way still gives its table (validate's ladder, whose errors against the full
  // model show what that costs; the hard high-saddle at grids of 2° and coarser).
  bool require_closed_turn = true;
  // Set: a non-periodic table over the range (range_intervals); empty: one period of a
  // revolute coordinate that turns fully.
  std::optional<ExtractRange> range;
  // Configurations of rank loss between grid points (the full model's scan), where a constraint
  // force may have a pole the grid samples do not show: each is checked as a singular grid point
  // is (sweep_refine.hpp) when the sweep passes it, and a pole found is listed. [rad or m]
  std::vector<double> singular_hints;
};

// Below this conditioning at a grid point, rank loss may lie between grid points: the caller
// (validate's extract_from_full) scans for it and extracts again with singular_hints.
inline constexpr double kScanBelowConditioning = 0.05;

// Samples one period of a revolute independent coordinate, starting from the grid point
// nearest the scene's initial q and continuing from point to point (so the full model stays
// on its assembled branch); with options.range, the range from its minimum upward instead
// (non-periodic columns, m1 of the integrated method integrated from the minimum). The step must divide 360° evenly (check_grid_step, before any
// allocation). Throws TableError on bad options, NumericalError when a sample is not finite.
Samples extract_samples(KinetostaticSource& source, const models::Scene& scene, const ExtractOptions& options);

// A periodic sweep that does not come back to its start: one more sample at the first grid
// point plus a turn differs from the first (m1 or a velocity ratio beyond 1e-7 of its column's
// size), so the sweep changed assembly branch on the way, stepping over a dead point (a blocked
// range narrower than a grid step) or an unflagged crossing. The caller (validate's
// extract_from_full) then looks for dead points and samples the range between them.
class SweepNotClosed : public TableError {
 public:
  using TableError::TableError;
};

// A point force's points meeting (models::PointForceMeeting) between two grid points or on one:
// a range table may end short of it (validate/analysis/build_reduced.cpp).
using models::PointForceMeeting;
// The edge kind of a range table that ends short of such a meeting.
inline constexpr const char* kPointForceMeetingEdge = "point force meeting";

}  // namespace rdyn::reduced
