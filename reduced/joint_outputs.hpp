// Every joint's motion and reaction and the shaking load (scene `outputs.joints`,
// `outputs.reactions`, `outputs.shaking`): the column names both models write, and the reduced
// model's route to them from its table (joint positions p_<j>, velocity ratios r_<j>, and one
// constraint line per reaction component). No Simbody.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/samples.hpp"
#include "reduced/table.hpp"

namespace rdyn::reduced {

// The column names (models/scene.hpp).
using models::joint_output_names;

// Whether the scene asks for any of these columns.
inline bool wants_joint_outputs(const models::Scene& s) {
  return !s.outputs.joints.empty() || !s.outputs.reactions.empty() || s.outputs.shaking;
}

// Table columns (extract_samples adds them when wants_joint_outputs): per joint j, p_<j> =
// q_j(q) − k_j·q, periodic over a turn of q, and k_<j> = k_j, the turns joint j makes per turn
// of q (1 for the independent joint, 0 for a rocker or a prismatic joint), so q_j = p_<j> + k_j q.
// Called by extract_samples with the grid (q [rad], step h), the velocity ratios r[j][i] and the
// joint coordinates p[j][i] as the sweep continued them.
void add_joint_position_columns(const models::Scene& scene, const std::vector<double>& q, double h,
                                const std::vector<std::vector<double>>& r, const std::vector<std::vector<double>>& p,
                                Samples& samples);

// Internal constraint-force requests the reduced model needs for the reactions: one line per
// reaction component, R_<joint>_gx and R_<joint>_gy (the joint's force on its child along the
// ground's x and y axes), for each revolute joint whose reaction is output and for the joints
// Newton–Euler of a loop's body uses (below). The kinetostatic calls give them along the child
// frame's axes; extract_samples turns each pair into ground at every grid point
// (turn_reaction_lines_to_ground), so the table interpolates the ground-frame reaction that is
// output. In the child frame a body geared 30:1 to q turns its weight 30 times per turn of q:
// 36 grid points alias that harmonic (issue #23, a quick-return's motor joint was off by 2 m g).
inline std::string internal_request_name(const std::string& joint, char axis) {
  return std::string("R_") + joint + "_g" + axis;
}
// Turns each pair of reaction lines (internal requests R_<j>_gx, _gy, sampled along the child
// frame's x and y) into the ground frame at every grid point: every column of the line —
// me1_, me2_, Qx_cons_, rx_, wx_, Qxpf_ — by the child's angle there (Σ offset + p_ + k_·q of
// the revolute joints from ground to the child; the p_/k_ columns must be present). The lines
// are linear in q̈, q̇² and the loads, so the turned lines are exact at the grid points. A
// pair's poles become the union of both. Called by extract_samples.
void turn_reaction_lines_to_ground(const models::Scene& scene, Samples& samples);

// The revolute joints whose reaction lines the scene's requested reactions read: each revolute
// joint in outputs.reactions, and the joints Newton–Euler of a loop's body or a prismatic
// joint's child uses. Throws TableError for reactions the reduced model cannot give (below).
std::vector<std::string> reaction_line_joints(const models::Scene& scene);
// `scene` plus those requests (extract and build the reduced model from it). Throws TableError
// for reactions the reduced model cannot give: a prismatic joint's, or a loop neither of whose
// bodies hangs from revolute joints only, touches no spring and no other loop.
models::Scene with_reaction_requests(const models::Scene& scene);

// The reactions the reduced model can give and the others with the reason (with_reaction_requests'
// message for each alone). `scene` keeps those it can; validate compares them and names the
// others, and a run of a scene that asked for `reactions: all` leaves the others out.
struct ReducedReactions {
  models::Scene scene;
  std::vector<std::pair<std::string, std::string>> not_given;  // reaction name, why
};
ReducedReactions split_reduced_reactions(const models::Scene& scene);

// One body's planar motion at one state (ground frame): angle [rad], rate [rad/s] and
// acceleration [rad/s²], its origin [m] and the origin's acceleration [m/s²].
struct BodyMotion {
  double th = 0, w = 0, al = 0, x = 0, y = 0, ax = 0, ay = 0;
};

// What the joint outputs of one state read, fixed once from the scene, the table and the run's
// constraint lines: add_joint_outputs evaluates it per row, the runtime per step
// (reduced/runtime.hpp), so both give the same numbers.
struct JointOutputModel {
  models::Scene scene;               // the scene whose joint outputs these are
  std::vector<std::string> names;    // joint_output_names(scene): calc_joint_outputs' order
  std::vector<int> c_p, c_k, c_r;    // per joint: the table's p_, k_, r_ columns
  std::vector<int> parent, child;    // per joint: body indices (parent −1: ground)
  std::vector<int> order;            // joints with parents before children (a tree rooted at ground)
  std::vector<int> line_x, line_y;   // per joint: its reaction lines R_<j>_cx, _cy among the forces (−1: none)
  std::vector<int> loop_body, loop_sign;  // per loop a reaction needs: the body that balances it, ±1 (−1, 0: none)
  double gx = 0.0, gy = 0.0;         // gravity [m/s²] (0 when disabled)
};
// The table columns make_joint_output_model reads (the reaction lines' are the reduced model's):
// p_<j>, k_<j> and r_<j> of every joint j, in the scene's joint order.
std::vector<std::string> joint_output_columns(const models::Scene& scene);
// `force_names`: the run's constraint forces in the order calc_joint_outputs gets their values
// (a reduced model's force_names). Throws TableError when the table lacks a joint's p_, k_ or r_
// column (extracted without joint outputs) or the forces a reaction line, or for a reaction
// the reduced model cannot give.
JointOutputModel make_joint_output_model(const models::Scene& scene, const Table& table,
                                         const std::vector<std::string>& force_names);

// Scratch of one evaluation, sized once: calc_joint_outputs allocates nothing.
struct JointOutputWorkspace {
  explicit JointOutputWorkspace(const JointOutputModel& m);
  std::vector<double> qj, uj, aj;  // joint coordinates [rad or m], rates, accelerations
  std::vector<BodyMotion> body;    // per body
  std::vector<double> cax, cay, cx, cy;  // per body: centre of mass acceleration [m/s²], position [m]
};

// The joint outputs at (q, q̇, q̈) with the run's constraint forces there (`forces`, in the order
// make_joint_output_model was given) into out[0 … names.size()): joint motion q_j = p_j + k_j q,
// q̇_j = r_j q̇, q̈_j = r_j q̈ + (dr_j/dq) q̇²; revolute reactions from their lines turned into
// ground by the child's angle; loops and prismatic joints and the shaking load by Newton–Euler
// with the bodies' accelerations from planar tree kinematics. Allocation-free.
void calc_joint_outputs(const JointOutputModel& m, const Table& table, JointOutputWorkspace& ws, double q,
                        double qdot, double qddot, const double* forces, double* out);

// Fills ts.columns with joint_output_names(scene) for a reduced run of the model built from
// with_reaction_requests(scene), from the table (p_, k_, r_ columns, dr_/dq of the cubic) and
// the internal forces, which it then removes from ts.forces. Loops and shaking by Newton–Euler
// with the bodies' accelerations from the joints' motion (planar tree kinematics). Throws
// TableError when the table lacks the columns (extracted without joint outputs).
void add_joint_outputs(const models::Scene& scene, const ReducedModel& model, models::TimeSeries& ts);

}  // namespace rdyn::reduced
