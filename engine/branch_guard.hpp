// Branch guard of the full model's forward dynamics (issue #22 item 2): the integrated motion
// must stay on the assembly branch it started on. Through a singular configuration (the loop
// Jacobian loses rank, e.g. a parallelogram's aligned position, where the antiparallelogram
// branch crosses) an integrator can leave on the other branch; energy is conserved there too,
// so the energy balance cannot see it. The guard continues the assembly of its own workspace
// along the starting branch to the integrated independent coordinate (follow_branch) and
// compares every joint coordinate with the integrated one. Plain records; no Simbody type.
#pragma once

#include <string>
#include <vector>

#include "engine/full_model.hpp"

namespace rdyn::engine {

// Tolerance of the comparison: kBranchTolerance_rad for a revolute joint, kBranchTolerance_rel ×
// the mechanism's size (calc_length_scale) for a prismatic one. On the branch the two
// configurations differ only by the constraint projections (the integrator's constraint
// tolerance ≤ 1e-10 m, the guard's 1e-12), amplified by 1/σ_min of the loop Jacobian near a
// singular configuration (σ_min/σ_max ≈ 0.3 × distance in rad, kinetostatic.hpp): below 1e-6 rad
// everywhere but within ~1e-4 rad of the singular point itself, whatever the integrator's
// accuracy (its error moves the configuration along the branch, which the guard follows to the
// same q). The other branch leaves the crossing at an angle, by ~the distance travelled past it,
// so a switch is flagged ~1e-3 rad past the crossing, far below anything a validation grid sees.
inline constexpr double kBranchTolerance_rad = 1e-3;
inline constexpr double kBranchTolerance_rel = 1e-3;
// Longest move of the guard's continuation: 0.1 rad (or 0.05 × the mechanism's size); a move is
// halved while Newton corrects its second-order prediction by more than a tenth of the smallest
// tolerance (1e-4 rad): the prediction's own error stays an order below what the guard flags, and
// a move landing on a branch that passes within a tolerance is refused (follow_branch).
inline constexpr double kBranchMaxMove_rad = 0.1;
inline constexpr double kBranchMaxMove_rel = 0.05;
inline constexpr double kBranchCorrectionFraction = 0.1;

// The guard's workspace: its own configuration on the starting branch.
struct BranchGuard {
  explicit BranchGuard(const FullModel& model);
  FullWorkspace ws;              // kinetostatic workspace continued from sample to sample
  std::vector<double> tolerance;  // per scene joint [rad or m]
  double max_move = 0.0;          // follow_branch's longest move [rad or m]
  double max_correction = 0.0;    // follow_branch's largest accepted correction [rad or m]
};

// The worst joint of one comparison.
struct BranchCheck {
  bool on_branch = true;
  double q = 0.0;            // the independent coordinate compared at [rad or m]
  int joint = -1;            // scene joint index of the largest deviation relative to its tolerance
  double integrated = 0.0;   // that joint's integrated coordinate [rad or m]
  double expected = 0.0;     // its coordinate on the starting branch at the same q [rad or m]
  double tolerance = 0.0;    // [rad or m]
};

// Continues the guard to the independent coordinate q and compares every scene joint's
// coordinate `joint_q` (revolute ones modulo a turn) with the starting branch's. Throws
// EngineError when the guard cannot continue (a dead point inside the domain: not expected).
BranchCheck calc_branch_check(const FullModel& model, BranchGuard& guard, double q,
                              const std::vector<double>& joint_q);

// The message of a switch: the time, the joint and both values.
std::string describe_branch_switch(const FullModel& model, const BranchCheck& c, double t_s, double t_prev_s);

}  // namespace rdyn::engine
