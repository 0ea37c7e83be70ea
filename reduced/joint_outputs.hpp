// Every joint's motion and reaction and the shaking load (scene `outputs.joints`,
// `outputs.reactions`, `outputs.shaking`): the column names both models write, and the reduced
// model's route to them from its table (joint positions p_<j>, velocity ratios r_<j>, and one
// constraint line per reaction component). No Simbody.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/timeseries.hpp"

namespace rdyn::reduced {

// Column names, in this order: per outputs.joints q_<j>, qdot_<j>, qddot_<j> [rad or m, /s, /s²];
// per outputs.reactions R_<n>_x, R_<n>_y [N] (ground frame) and, for a prismatic joint,
// R_<n>_normal [N] (along the axis turned +90°) and R_<n>_M [N·m] (about the child point); then
// shaking_x, shaking_y [N], shaking_M [N·m] (about the ground origin) when outputs.shaking.
std::vector<std::string> joint_output_names(const models::Scene& scene);

// Whether the scene asks for any of these columns.
inline bool wants_joint_outputs(const models::Scene& s) {
  return !s.outputs.joints.empty() || !s.outputs.reactions.empty() || s.outputs.shaking;
}

}  // namespace rdyn::reduced
