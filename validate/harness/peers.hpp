// Peer engines beside rdyn's two models (issue #11): MuJoCo runs of the same scene, exported as
// MJCF (models/mjcf_export.hpp) and started from the full model's assembled state, timed and
// compared like the full model's ladder.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/harness/harness.hpp"
#include "validate/harness/ladder_plan.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {

// Every scene joint's coordinate and rate at the scene's initial q, q̇, from the full model's
// assembly (a kinetostatic call with the loads off): closes the loops for the MJCF export and
// starts a peer in the full model's state. Throws EngineError when the mechanism cannot assemble.
struct JointState {
  std::vector<double> q;  // [rad or m], scene joint order
  std::vector<double> u;  // [rad/s or m/s]
};
JointState calc_initial_joint_state(const models::Scene& scene);

// Peers `rdyn validate --peers` accepts, and whether this build can run `name` (MuJoCo only when
// CMake found it). check_peers throws ArgumentError (exit 2) for an unknown, absent or repeated
// peer.
inline const std::vector<std::string> kPeers{"mujoco"};
void check_peers(const std::vector<std::string>& peers);

// Stage 3b: for each peer, an Euler and an RK4 ladder over plan.peer_steps_s (each step shortened
// to fill the output interval with whole steps), each run timed by plan.peer_repeats and compared
// with the reference; a run that stops (MuJoCo's motion blew up) is recorded with its reason.
void run_peer_ladders(const models::Scene& scene, const std::vector<std::string>& peers, const LadderPlan& plan,
                      ValidationResult& v, Progress& progress);

// Stage 4 for the peers (no simulation): Pareto flags within each ladder and the reduced model's
// speedup over it at matched error (validate/harness/pareto.hpp, calc_matched_speedup).
void analyse_peers(ValidationResult& v);

}  // namespace rdyn::validate
