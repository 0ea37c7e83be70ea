#include "reduced/joint_outputs.hpp"

namespace rdyn::reduced {

std::vector<std::string> joint_output_names(const models::Scene& s) {
  std::vector<std::string> n;
  for (const auto& j : s.outputs.joints) {
    n.push_back("q_" + j);
    n.push_back("qdot_" + j);
    n.push_back("qddot_" + j);
  }
  for (const auto& r : s.outputs.reactions) {
    n.push_back("R_" + r + "_x");
    n.push_back("R_" + r + "_y");
    const auto* j = s.find_joint(r);
    if (j && j->type == models::JointType::Prismatic) {
      n.push_back("R_" + r + "_normal");
      n.push_back("R_" + r + "_M");
    }
  }
  if (s.outputs.shaking) {
    n.push_back("shaking_x");
    n.push_back("shaking_y");
    n.push_back("shaking_M");
  }
  return n;
}

}  // namespace rdyn::reduced
