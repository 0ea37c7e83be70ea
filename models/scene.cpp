#include "models/scene.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>

namespace rdyn::models {

namespace {
std::string format_error(const std::string& file, int line, const std::string& field,
                         const std::string& message) {
  std::string where = file.empty() ? std::string("<scene>") : file;
  if (line > 0) where += fmt::format(":{}", line);
  if (!field.empty()) where += fmt::format(": field '{}'", field);
  return where + ": " + message;
}
}  // namespace

SceneError::SceneError(std::string file, int line, std::string field, const std::string& message)
    : std::runtime_error(format_error(file, line, field, message)),
      file_(std::move(file)),
      line_(line),
      field_(std::move(field)) {}

const Body* Scene::find_body(const std::string& n) const {
  for (const auto& b : bodies)
    if (b.name == n) return &b;
  return nullptr;
}

const Joint* Scene::find_joint(const std::string& n) const {
  for (const auto& j : joints)
    if (j.name == n) return &j;
  return nullptr;
}

int Scene::joint_index(const std::string& n) const {
  for (size_t i = 0; i < joints.size(); ++i)
    if (joints[i].name == n) return static_cast<int>(i);
  return -1;
}

int Scene::body_index(const std::string& n) const {
  for (size_t i = 0; i < bodies.size(); ++i)
    if (bodies[i].name == n) return static_cast<int>(i);
  return -1;
}

void check_scene(const Scene& s) {
  auto fail = [&](const std::string& field, const std::string& msg) {
    throw SceneError(s.source_file, 0, field, msg);
  };
  auto finite = [](double v) { return std::isfinite(v); };
  auto is_body_or_ground = [&](const std::string& n) { return n == kGround || s.find_body(n); };

  std::set<std::string> names;
  for (const auto& b : s.bodies) {
    const std::string f = "bodies." + b.name;
    if (b.name.empty() || b.name == kGround) fail("bodies", "a body needs a name other than 'ground'");
    if (!names.insert(b.name).second) fail(f, "duplicate body name");
    if (!finite(b.mass_kg) || b.mass_kg <= 0.0)
      fail(f + ".mass_kg", fmt::format("mass must be positive and finite (got {})", b.mass_kg));
    if (!finite(b.inertia_kgm2) || b.inertia_kgm2 <= 0.0)
      fail(f + ".inertia_kgm2",
           fmt::format("centroidal inertia must be positive and finite (got {})", b.inertia_kgm2));
    if (!finite(b.com_m.x) || !finite(b.com_m.y)) fail(f + ".com_m", "not finite");
  }
  if (s.bodies.empty()) fail("bodies", "the scene has no bodies");

  // Tree: every body is the child of exactly one joint, and walking parents reaches ground.
  std::map<std::string, std::string> parent_of;
  std::set<std::string> joint_names;
  for (const auto& j : s.joints) {
    const std::string f = "joints." + j.name;
    if (!joint_names.insert(j.name).second) fail(f, "duplicate joint name");
    if (!is_body_or_ground(j.parent)) fail(f + ".parent", "unknown body '" + j.parent + "'");
    if (!s.find_body(j.child)) fail(f + ".child", "unknown body '" + j.child + "'");
    if (parent_of.count(j.child))
      fail(f + ".child", "body '" + j.child + "' is already the child of another joint; "
                             "close loops with 'loops', not with a second joint");
    parent_of[j.child] = j.parent;
    if (j.type == JointType::Prismatic) {
      const double n = std::hypot(j.axis.x, j.axis.y);
      if (!finite(n) || n < 1e-12) fail(f + ".axis", "prismatic axis must be a non-zero vector");
    }
    if (!finite(j.guess) || !finite(j.offset_rad)) fail(f, "guess/offset not finite");
  }
  for (const auto& b : s.bodies) {
    if (!parent_of.count(b.name))
      fail("bodies." + b.name, "body is not attached by any joint (every body needs one)");
    std::string cur = b.name;
    for (size_t hops = 0; cur != kGround; ++hops) {
      if (hops > s.bodies.size()) fail("joints", "joints form a cycle through '" + b.name + "'");
      cur = parent_of[cur];
    }
  }

  for (const auto& l : s.loops) {
    if (!is_body_or_ground(l.body_a)) fail("loops." + l.name + ".body_a", "unknown body");
    if (!is_body_or_ground(l.body_b)) fail("loops." + l.name + ".body_b", "unknown body");
    if (l.body_a == l.body_b) fail("loops." + l.name, "a loop must join two different bodies");
  }
  for (const auto& g : s.gears) {
    const Joint* a = s.find_joint(g.driver);
    const Joint* b = s.find_joint(g.driven);
    if (!a) fail("gears." + g.name + ".driver", "unknown joint '" + g.driver + "'");
    if (!b) fail("gears." + g.name + ".driven", "unknown joint '" + g.driven + "'");
    if (a->type != JointType::Revolute || b->type != JointType::Revolute)
      fail("gears." + g.name, "gears couple two revolute joints");
    if (!finite(g.ratio) || g.ratio == 0.0) fail("gears." + g.name + ".ratio", "must be non-zero");
  }

  // Mobility (Grübler for planar joints): each joint adds one coordinate, each loop
  // removes two, each gear one.
  const int dof = static_cast<int>(s.joints.size()) - 2 * static_cast<int>(s.loops.size()) -
                  static_cast<int>(s.gears.size());
  if (dof != 1)
    fail("joints", fmt::format("the mechanism has {} degrees of freedom ({} joints, {} loops, "
                               "{} gears); rdyn needs exactly 1",
                               dof, s.joints.size(), s.loops.size(), s.gears.size()));

  if (!s.find_joint(s.independent))
    fail("independent", "unknown joint '" + s.independent + "'");

  auto check_joint_ref = [&](const std::string& field, const std::string& j) {
    if (!s.find_joint(j)) fail(field, "unknown joint '" + j + "'");
  };
  for (const auto& t : s.joint_torques) {
    check_joint_ref("loads." + t.name + ".joint", t.joint);
    if (!finite(t.value)) fail("loads." + t.name + ".value", "not finite");
    if (t.active_when) check_joint_ref("loads." + t.name + ".active_when.joint", t.active_when->joint);
  }
  for (const auto& r : s.resistances) {
    if (!s.find_body(r.body)) fail("loads." + r.name + ".body", "unknown body '" + r.body + "'");
    if (!finite(r.coefficient) || r.coefficient < 0.0)
      fail("loads." + r.name + ".coefficient", "must be finite and non-negative");
  }
  for (const auto& sp : s.springs) {
    if (!is_body_or_ground(sp.body_a) || !is_body_or_ground(sp.body_b))
      fail("loads." + sp.name, "unknown body");
    if (!finite(sp.stiffness_N_per_m) || sp.stiffness_N_per_m < 0.0 ||
        !finite(sp.rest_length_m) || sp.rest_length_m < 0.0)
      fail("loads." + sp.name, "stiffness and rest length must be finite and non-negative");
  }
  for (const auto& m : s.motors) {
    check_joint_ref("loads." + m.name + ".joint", m.joint);
    if (!finite(m.stall_torque) || !finite(m.no_load_speed) || m.no_load_speed == 0.0)
      fail("loads." + m.name, "stall torque must be finite and no-load speed non-zero");
  }
  for (const auto& c : s.outputs.constraint_forces) {
    const Joint* j = s.find_joint(c.joint);
    if (!j) fail("outputs.constraint_forces." + c.name + ".joint", "unknown joint '" + c.joint + "'");
    if (j->type != JointType::Revolute)
      fail("outputs.constraint_forces." + c.name, "constraint forces are offered on revolute joints");
    if (c.joint == s.independent)
      fail("outputs.constraint_forces." + c.name, "the independent coordinate's joint has no "
                                                  "constraint actuator; pick another joint");
    const double n = std::hypot(c.direction.x, c.direction.y);
    if (!finite(n) || n < 1e-12)
      fail("outputs.constraint_forces." + c.name + ".direction", "must be a non-zero vector");
  }
  for (const auto& b : s.outputs.bodies)
    if (!s.find_body(b)) fail("outputs.bodies", "unknown body '" + b + "'");

  const auto& sim = s.simulation;
  if (!finite(sim.duration_s) || sim.duration_s <= 0.0)
    fail("simulation.duration_s", "must be positive");
  if (!finite(sim.output_interval_s) || sim.output_interval_s <= 0.0)
    fail("simulation.output_interval_s", "must be positive");
  if (!finite(sim.tolerance) || sim.tolerance <= 0.0 || sim.tolerance >= 1.0)
    fail("simulation.tolerance", "must be in (0, 1)");
  if (!finite(s.initial.q) || !finite(s.initial.qdot)) fail("initial", "not finite");
  if (!finite(s.gravity.g_m_s2.x) || !finite(s.gravity.g_m_s2.y)) fail("gravity.g_m_s2", "not finite");
}

double resistance_torque(ResistanceLaw law, double c, double w) {
  switch (law) {
    case ResistanceLaw::Constant: return w > 0 ? -c : w < 0 ? c : 0.0;
    case ResistanceLaw::Viscous: return -c * w;
    case ResistanceLaw::Quadratic: return -c * w * std::abs(w);
  }
  return 0.0;
}

int dissipation_exponent(ResistanceLaw law) {
  return law == ResistanceLaw::Constant ? 1 : law == ResistanceLaw::Viscous ? 2 : 3;
}

std::optional<double> fixed_speed_ratio(const Scene& s, const std::string& body) {
  for (const auto& j : s.joints) {
    if (j.child != body || j.parent != kGround || j.type != JointType::Revolute) continue;
    if (j.name == s.independent) return 1.0;
    for (const auto& g : s.gears) {
      const Joint* driver = s.find_joint(g.driver);
      if (g.driven == j.name && g.driver == s.independent && driver->parent == kGround)
        return g.ratio;
    }
  }
  return std::nullopt;
}

}  // namespace rdyn::models
