// Reduced models extracted from the full model of a scene (engine + reduced together).
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "models/scene.hpp"
#include "reduced/extract.hpp"
#include "reduced/samples.hpp"

namespace rdyn::engine {
class FullModel;
}

namespace rdyn::validate {

// Wall time of extract_from_full by stage [ms] (issue #11 item 3).
struct ExtractionStages {
  double system_build_ms = 0.0;   // the Simbody system (engine::FullModel: topology, model stage)
  double assembly_ms = 0.0;       // the workspace: assembly at the initial q, one-DOF and branch checks
  double kinetostatics_ms = 0.0;  // the sweep over the grid (and a dead-point search for a range)
};

struct Extraction {
  reduced::Samples samples;
  double extraction_ms = 0.0;  // wall time of the kinetostatic calls [ms]
  ExtractionStages stages;     // extraction_ms by stage
  long calls = 0;              // kinetostatic calls made
  // Range tables: the range sampled and the dead points found (when not declared) [rad or m].
  std::optional<reduced::ExtractRange> range;
  std::optional<double> dead_min, dead_max;
};

// Builds the full model of the scene and samples its reduced parameters. A revolute without a
// declared range is swept as a full turn first; when it meets a dead point, or (with
// require_closed_turn, reduced::ExtractOptions) does not close its turn, the dead points are
// looked for and the range between them sampled; a periodic domain whose sweep does not close
// throws reduced::SweepNotClosed (exit 2, the message says why).
Extraction extract_from_full(const models::Scene& scene, double grid_deg, reduced::Method method,
                             bool require_closed_turn = true);

// The same on a full model already built (stages.system_build_ms 0): calibration's dead-point
// walk and its extraction share one system.
Extraction extract_from_full(const engine::FullModel& model, double grid_deg, reduced::Method method,
                             bool require_closed_turn = true);

// The larger half-grid miss (reduced::calc_half_grid_miss) of a periodic table's m1 and Q_cons (the
// conservative generalized force), with its column's name; NaN for a range table. Q_cons sees what
// m1 cannot: a rotor geared 25:1 to the crank and 2 mm out of balance has a constant m1 (miss
// 3e-9 at 10°) while its weight's torque turns 25 times a turn (Q_cons miss 1.2: at 10° the
// reduced q̈ was 4.2 % off and the motor's reaction 197 %, exit 0).
std::pair<std::string, double> calc_resolution_miss(const reduced::Samples& samples);
// The largest half-grid miss of a constraint line's force (the requested ones and the internal
// lines of joint outputs) along the turn at the scene's starting speed, each against its own
// peak, with the line's name; 0 for a range table or a scene without lines. An unbalanced
// flywheel geared 24:1, without gravity, has m1 and Q_cons resolved at 10° (2.9e-6, 0) while its
// bearing's reaction, ω² times a line that turns 24 times a turn, came out 199 % off with exit 0
// (its line misses 2.0).
std::pair<std::string, double> calc_line_resolution_miss(const reduced::Samples& samples, const models::Scene& scene);

// Above this half-grid miss (calc_resolution_miss) a default grid does not resolve the mechanism; kMinAutoGrid_deg (10° halved five times) is as far as it is halved: a five-bar
// whose slow crank is the coordinate, geared 20:1 to the fast one, misses 15 % at 1.25°, 2.5e-3
// at 0.625° and 6.9e-7 at 0.3125° (its extraction there 0.7 s).
inline constexpr double kAutoRefineMiss = 1e-3;
// Above this a line's force (calc_line_resolution_miss) has turns the half table cannot
// represent at all, and the table itself is at its limit: refined too. A line's half-grid miss
// says little about the table's own error below that (measured at 10°: the bicycle's knee 0.11,
// the slider-crank's rod 0.065, each within 1e-3 of the full model at 10°), while the lines
// that turn with a fast geared mass miss 2.0 (a flywheel 24:1, a rotor 25:1).
inline constexpr double kAutoRefineLineMiss = 0.25;
inline constexpr double kMinAutoGrid_deg = 0.3125;

// extract_from_full at grid_deg; when the grid is a default (`grid_given` false), a periodic
// table that does not resolve m1 or Q_cons (or whose constraint lines miss kAutoRefineLineMiss) — interpolated from every other grid point it misses the others
// by more than kAutoRefineMiss of its peak — is extracted again at half the step, down to
// kMinAutoGrid_deg, each step said on standard error. `grid_deg_used` gets the grid of the table
// returned. Measured misses at 10°: slider-crank 1.7e-7, bicycle 8e-5, fourbar 1.4e-4 (q̈ within
// 1e-5): kept; the light-flywheel bicycle 9.8e-3 (q̈ 1.1e-2 off): 5°; a Jansen leg 0.10 (q̈ 6 %
// off, exit 0): 2.5°, then every column within 4.5e-5 of the full model's peak.
Extraction extract_resolving(const models::Scene& scene, double grid_deg, bool grid_given, reduced::Method method,
                             double& grid_deg_used);
// The same on a full model already built (calibration's walk and extraction share one system);
// `say` false keeps the steps off standard error (a sweep's cases).
Extraction extract_resolving(const engine::FullModel& model, double grid_deg, bool grid_given, reduced::Method method,
                             bool say, double& grid_deg_used);

}  // namespace rdyn::validate
