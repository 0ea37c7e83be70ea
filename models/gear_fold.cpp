#include "models/gear_fold.hpp"

#include <cmath>

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

}  // namespace rdyn::models
