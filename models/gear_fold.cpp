#include "models/gear_fold.hpp"

#include <cmath>
#include <numeric>
#include <string>

#include <fmt/format.h>

namespace rdyn::models {

std::vector<bool> calc_foldable_gears(const Scene& s) {
  std::vector<bool> fold(s.gears.size(), false);
  for (size_t g = 0; g < s.gears.size(); ++g) {
    const auto& gear = s.gears[g];
    const Joint* driven = s.find_joint(gear.driven);
    const Joint* driver = s.find_joint(gear.driver);
    if (!driven || !driver) continue;
    const Body* body = s.find_body(driven->child);
    if (!body) continue;
    bool ok = driven->parent == kGround && driver->parent == kGround && driven->name != s.independent &&
              std::hypot(body->com_m.x - driven->child_point.x, body->com_m.y - driven->child_point.y) < 1e-12;
    for (const auto& name : s.outputs.bodies) ok &= name != body->name;
    for (const auto& j : s.joints) ok &= j.parent != body->name;
    for (const auto& l : s.loops) ok &= l.body_a != body->name && l.body_b != body->name;
    for (const auto& sp : s.springs) ok &= sp.body_a != body->name && sp.body_b != body->name;
    for (const auto& pf : s.point_forces)
      ok &= pf.body_a != body->name && pf.body_b != body->name &&
            (!pf.active_when || pf.active_when->joint != driven->name);
    for (const auto& t : s.joint_torques)
      ok &= t.joint != driven->name && (!t.active_when || t.active_when->joint != driven->name);
    for (const auto& m : s.motors) ok &= m.joint != driven->name;
    for (const auto& g2 : s.gears) ok &= &g2 == &gear || (g2.driver != driven->name && g2.driven != driven->name);
    for (const auto& c : s.outputs.constraint_forces) ok &= c.joint != driven->name;
    // A driver that is itself folded would carry the inertia into a body that is not built.
    for (size_t g2 = 0; g2 < g; ++g2) ok &= !(fold[g2] && s.gears[g2].driven == driver->name);
    fold[g] = ok;
  }
  return fold;
}

double calc_gear_offset(const Scene& s, const Gear& gear) {
  return s.find_joint(gear.driven)->guess - gear.ratio * s.find_joint(gear.driver)->guess;
}

std::vector<GearFold> calc_gear_folds(const Scene& s) {
  std::vector<GearFold> folds;
  const auto foldable = calc_foldable_gears(s);
  for (size_t g = 0; g < s.gears.size(); ++g) {
    if (!foldable[g]) continue;
    const auto& gear = s.gears[g];
    GearFold f;
    f.gear = static_cast<int>(g);
    f.driven_joint = s.joint_index(gear.driven);
    f.driver_joint = s.joint_index(gear.driver);
    f.body = s.body_index(s.joints[f.driven_joint].child);
    f.driver_body = s.body_index(s.joints[f.driver_joint].child);
    f.ratio = gear.ratio;
    f.q_offset = calc_gear_offset(s, gear);
    // ½ I (r u)² = ½ (r² I) u²: the driven body's kinetic energy on its driver.
    f.moved_inertia_kgm2 = gear.ratio * gear.ratio * s.bodies[f.body].inertia_kgm2;
    folds.push_back(f);
  }
  return folds;
}

int calc_turns_to_repeat(const Scene& scene, std::string& why) {
  why.clear();
  // Rate ratios ρ_j = q̇_j / q̇ of the joints geared to the independent one, by a walk over the
  // gears in both directions (q̇_driven = r·q̇_driver).
  std::vector<double> rho(scene.joints.size(), NAN);
  std::vector<std::string> via(scene.joints.size());
  const int ind = scene.joint_index(scene.independent);
  if (ind < 0) return 1;
  rho[ind] = 1.0;
  for (size_t pass = 0; pass < scene.gears.size(); ++pass)
    for (const auto& g : scene.gears) {
      const int a = scene.joint_index(g.driver), b = scene.joint_index(g.driven);
      if (a < 0 || b < 0 || !(g.ratio != 0.0)) continue;
      if (std::isfinite(rho[a]) && !std::isfinite(rho[b])) rho[b] = g.ratio * rho[a], via[b] = g.name;
      if (std::isfinite(rho[b]) && !std::isfinite(rho[a])) rho[a] = rho[b] / g.ratio, via[a] = g.name;
    }
  int k_all = 1;
  for (size_t j = 0; j < scene.joints.size(); ++j) {
    if (!std::isfinite(rho[j]) || static_cast<int>(j) == ind || scene.joints[j].type != JointType::Revolute) continue;
    int k = 1;
    while (k <= kMaxTurnsToRepeat && std::abs(k * rho[j] - std::round(k * rho[j])) > 1e-9 * k * std::max(1.0, std::abs(rho[j])))
      ++k;
    if (k > kMaxTurnsToRepeat) {
      why = fmt::format("gear '{}' turns '{}' {:.9g} turn(s) per turn of '{}', a ratio no whole number of turns "
                        "(up to {}) brings back",
                        via[j], scene.joints[j].name, rho[j], scene.independent, kMaxTurnsToRepeat);
      return 0;
    }
    const int k_new = std::lcm(k_all, k);
    if (k_new > kMaxTurnsToRepeat) {
      why = fmt::format("the gears need more than {} turns of '{}' to bring every joint back", kMaxTurnsToRepeat,
                        scene.independent);
      return 0;
    }
    if (k_new > k_all || (k > 1 && why.empty()))
      why = fmt::format("gear '{}' turns '{}' {:.9g} turn(s) per turn of '{}'", via[j], scene.joints[j].name, rho[j],
                        scene.independent);
    k_all = k_new;
  }
  return k_all;
}

}  // namespace rdyn::models
