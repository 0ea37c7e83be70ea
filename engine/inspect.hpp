// What a newcomer needs while writing a scene (`rdyn inspect`): the configuration the full
// model assembles at t = 0, its degrees of freedom, the loops' closure gaps, and the range
// of the independent coordinate found by continuation (full turn, or the dead points that
// bound it). Plain records; no Simbody type here.
#pragma once

#include <string>
#include <vector>

#include "engine/full_model.hpp"

namespace rdyn::engine {

// One scene joint at the assembled configuration.
struct AssembledJoint {
  std::string name;
  bool revolute = true;
  double q = 0.0;      // assembled coordinate [rad or m] (revolute: as Simbody continued it, not wrapped)
  double guess = 0.0;  // the scene's guess [rad or m]
};

// One scene body at the assembled configuration (ground frame).
struct AssembledBody {
  std::string name;
  double x_m = 0.0, y_m = 0.0;  // body frame origin [m]
  double angle_rad = 0.0;       // body frame rotation about z [rad]
  double com_x_m = 0.0, com_y_m = 0.0;  // centre of mass [m]
};

struct LoopGap {
  std::string name;
  double gap_m = 0.0;  // |p_a − p_b| after assembly [m]
};

// Joint coordinates, constraint rows and the rank of the constraint Jacobian ∂(loops, gears)/∂u
// (the engine's own count; full_model.cpp, calc_mobility): dof = mobilities − rank.
struct MobilityCount {
  int mobilities = 0, rows = 0, rank = 0;
};

// Range of the independent coordinate reachable from the assembled configuration by
// continuation on its branch.
struct CoordinateRange {
  bool full_turn = false;  // revolute: a whole turn walked without a dead point
  double q_min = 0.0, q_max = 0.0;  // [rad or m] (full turn: q0 − π, q0 + π)
  // Each end: a dead point (the loops cannot close beyond it, located to kDeadPointTolerance),
  // or the end of the search (prismatic coordinates are searched to ± kSearchSpan · length scale).
  bool min_is_dead_point = false, max_is_dead_point = false;
};

// Dead points are located to this width of the independent coordinate [rad or m]; the
// continuation step starts at 2° (or 2 % of the mechanism's length scale) and is quartered on
// each failed projection until it is narrower than this.
inline constexpr double kDeadPointTolerance = 1e-6;
// A prismatic coordinate is searched to this many length scales (the largest distance of a
// scene point from its frame's origin) on either side of its initial value.
inline constexpr double kSearchSpan = 10.0;

struct Inspection {
  std::vector<AssembledJoint> joints;
  std::vector<AssembledBody> bodies;
  MobilityCount mobility;
  std::vector<LoopGap> loops;
  CoordinateRange range;
  double length_scale_m = 0.0;  // largest |point| of the scene (warnings and prismatic steps) [m]
  std::vector<std::string> warnings;
};

// Assembles the scene at its initial q (as every run does), reports the configuration and
// walks the independent coordinate both ways on the assembled branch. Throws EngineError when
// the scene cannot assemble (a loop that cannot close, not one degree of freedom, the other
// branch than the one named) and models::NumericalError when a configuration is not finite.
Inspection calc_inspection(const FullModel& model);

// The assembled configuration only (no range walk): every joint coordinate and body pose at
// t = 0, and the warnings of an assembly that landed far from the guesses (> kFarFromGuess_deg
// for a revolute joint, > kFarFromGuess_fraction of the length scale for a prismatic one).
Inspection calc_assembly(const FullModel& model);
inline constexpr double kFarFromGuess_deg = 20.0;
inline constexpr double kFarFromGuess_fraction = 0.10;

}  // namespace rdyn::engine
