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
// reaction component, R_<joint>_cx and R_<joint>_cy (the joint's force on its child along the
// child frame's x and y axes), for each revolute joint whose reaction is output and for the
// joints Newton–Euler of a loop's body uses (below).
inline std::string internal_request_name(const std::string& joint, char axis) {
  return std::string("R_") + joint + "_c" + axis;
}
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

// Fills ts.columns with joint_output_names(scene) for a reduced run of the model built from
// with_reaction_requests(scene), from the table (p_, k_, r_ columns, dr_/dq of the cubic) and
// the internal forces, which it then removes from ts.forces. Loops and shaking by Newton–Euler
// with the bodies' accelerations from the joints' motion (planar tree kinematics). Throws
// TableError when the table lacks the columns (extracted without joint outputs).
void add_joint_outputs(const models::Scene& scene, const ReducedModel& model, models::TimeSeries& ts);

}  // namespace rdyn::reduced
