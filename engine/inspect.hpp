// What a newcomer needs while writing a scene (`rdyn inspect`): the configuration the full
// model assembles at t = 0, its degrees of freedom, the loops' closure gaps, and the domain of
// the independent coordinate exactly as the models use it (engine/independent_range.hpp: full
// turn, declared range, or the dead points less the kDeadPointMargin of 1 %). Plain records; no Simbody type.
#pragma once

#include <string>
#include <vector>

#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"

namespace rdyn::engine {

// One scene joint at the assembled configuration.
struct AssembledJoint {
  std::string name;
  bool revolute = true;
  double q = 0.0;      // assembled coordinate [rad or m] (revolute: within half a turn of the guess)
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

struct Inspection {
  std::vector<AssembledJoint> joints;
  std::vector<AssembledBody> bodies;
  MobilityCount mobility;
  std::vector<LoopGap> loops;
  // The domain extraction, both models' domain stop and run.json use (calc_independent_domain);
  // not set by calc_assembly.
  IndependentDomain range;
  double length_scale_m = 0.0;  // calc_length_scale: the mechanism's size (warnings, prismatic moves) [m]
  std::vector<std::string> warnings;
};

// Assembles the scene at its initial q (as every run does), reports the configuration and the
// independent coordinate's domain from calc_independent_domain. Throws EngineError when the
// scene cannot assemble (a loop that cannot close, not one degree of freedom, the other branch
// than the one named) or its domain is refused (a declared range across a dead point, an
// initial q within the margin of a dead point, the walk's move budget), and
// models::NumericalError when a configuration is not finite. A prismatic coordinate meeting
// fewer than two dead points is no error: the domain is unbounded and a warning says why.
Inspection calc_inspection(const FullModel& model);

// The assembled configuration only (no range walk): every joint coordinate and body pose at
// t = 0, and the warnings of an assembly that landed far from the guesses (> kFarFromGuess_deg
// for a revolute joint, > kFarFromGuess_fraction of the length scale for a prismatic one).
Inspection calc_assembly(const FullModel& model);
inline constexpr double kFarFromGuess_deg = 20.0;
inline constexpr double kFarFromGuess_fraction = 0.10;

}  // namespace rdyn::engine
