#include "engine/branch_guard.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "engine/full_model_impl.hpp"
#include "engine/independent_range.hpp"
#include "engine/kinetostatic.hpp"

namespace rdyn::engine {

using namespace SimTK;

BranchGuard::BranchGuard(const FullModel& model) : ws(model) {
  const auto& sc = model.scene();
  const double scale_m = calc_length_scale(sc);
  for (const auto& j : sc.joints)
    tolerance.push_back(j.type == models::JointType::Revolute ? kBranchTolerance_rad : kBranchTolerance_rel * scale_m);
  const bool revolute = sc.joints[model.impl().independent].type == models::JointType::Revolute;
  max_move = revolute ? kBranchMaxMove_rad : kBranchMaxMove_rel * scale_m;
  max_correction = kBranchCorrectionFraction * *std::min_element(tolerance.begin(), tolerance.end());
}

BranchCheck calc_branch_check(const FullModel& model, BranchGuard& guard, double q,
                              const std::vector<double>& joint_q) {
  const auto& m = model.impl();
  follow_branch(model, guard.ws, q, guard.max_move, guard.max_correction);
  const State& s = guard.ws.impl().state;
  BranchCheck out;
  double worst = 0.0;  // largest |deviation| / tolerance
  for (size_t j = 0; j < m.scene.joints.size() && j < joint_q.size(); ++j) {
    const double g = m.joint_q(s, static_cast<int>(j));
    const bool rev = m.scene.joints[j].type == models::JointType::Revolute;
    // Continuation may relabel an angle by a turn: the same configuration.
    const double d = rev ? std::remainder(joint_q[j] - g, 2 * Pi) : joint_q[j] - g;
    const double r = std::isfinite(d) ? std::abs(d) / guard.tolerance[j] : INFINITY;
    if (out.joint < 0 || r > worst) {
      worst = r;
      out = {true, q, static_cast<int>(j), joint_q[j], g, guard.tolerance[j]};
    }
  }
  out.on_branch = !(worst > 1.0);
  return out;
}

std::string describe_branch_switch(const FullModel& model, const BranchCheck& c, double t_s, double t_prev_s) {
  const auto& sc = model.scene();
  const auto& jt = sc.joints[c.joint];
  const bool rev = jt.type == models::JointType::Revolute;
  auto show = [rev](double v) { return rev ? fmt::format("{:.6g}°", v * 180 / Pi) : fmt::format("{:.6g} m", v); };
  // An angle shown within half a turn of the expected one (continuation may relabel it by turns).
  const double integrated = rev ? c.expected + std::remainder(c.integrated - c.expected, 2 * Pi) : c.integrated;
  return fmt::format(
      "full model switched assembly branch between t = {:.6g} s and t = {:.6g} s: joint '{}' is at {} but the branch "
      "the run started on has it at {} at the same {} {} (tolerance {}): the integration passed a singular "
      "configuration (the loop Jacobian loses rank there and branches cross) and left on another branch; try "
      "cpodes (it holds the hard parallelogram's branch at 1e-7 where rkmerson at 1e-9 does not) or another tolerance",
      t_prev_s, t_s, jt.name, show(integrated), show(c.expected), sc.independent,
      format_coordinate(c.q, sc.joints[model.impl().independent].type == models::JointType::Revolute).substr(2),
      show(c.tolerance));
}

}  // namespace rdyn::engine
