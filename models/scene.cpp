#include "models/scene.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <utility>
#include <vector>

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
      field_(std::move(field)),
      message_(message) {}

int Scene::line_of(const std::string& key) const {
  const auto it = key_lines.find(key);
  return it == key_lines.end() ? 0 : it->second;
}

std::string Scene::field_of(const std::string& key) const {
  const auto it = key_overrides.find(key);
  return it == key_overrides.end() ? key : "--set " + it->second;
}

std::string where(const Scene& scene, const std::string& key) {
  std::string w = scene.source_file.empty() ? std::string("<scene>") : scene.source_file;
  if (const int line = scene.line_of(key); line > 0) w += fmt::format(":{}", line);
  return w + fmt::format(": field '{}'", scene.field_of(key));
}

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

bool is_valid_name(const std::string& n) {
  auto head = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; };
  auto tail = [&](char c) { return head(c) || (c >= '0' && c <= '9') || c == '-'; };
  if (n.empty() || n.size() > limits::kMaxNameLength || !head(n[0])) return false;
  return std::all_of(n.begin() + 1, n.end(), tail);
}

namespace {

// Shows a name in a message without letting it break the message (newlines, quotes).
std::string printable(const std::string& n) {
  std::string out;
  for (char c : n.substr(0, 80)) {
    const auto u = static_cast<unsigned char>(c);
    out += (u < 0x20 || u == 0x7f || c == '\'') ? fmt::format("\\x{:02x}", u) : std::string(1, c);
  }
  return n.size() > 80 ? out + "…" : out;
}

// Check helpers: each throws SceneError(file, 0, field, message) on the first violation.
}  // namespace

std::string invalid_name_message(const std::string& n) {
  return fmt::format(
      "'{}' is not a valid name: 1 to {} characters from A-Z a-z 0-9 _ -, starting with a "
      "letter or '_'",
      printable(n), limits::kMaxNameLength);
}

namespace {

struct Checker {
  const Scene& s;

  [[noreturn]] void fail(const std::string& field, const std::string& msg) const {
    throw SceneError(s.source_file, 0, field, msg);
  }
  void in_range(const std::string& field, double v, double lo, double hi, const char* unit) const {
    if (!std::isfinite(v) || v < lo || v > hi)
      fail(field, fmt::format("must be in [{:g}, {:g}]{}{} (got {:g})", lo, hi, *unit ? " " : "",
                              unit, v));
  }
  void abs_at_most(const std::string& field, double v, double hi, const char* unit) const {
    if (!std::isfinite(v) || std::abs(v) > hi)
      fail(field, fmt::format("must be finite with |value| ≤ {:g}{}{} (got {:g})", hi,
                              *unit ? " " : "", unit, v));
  }
  void point(const std::string& field, Vec2 p) const {
    abs_at_most(field + "[0]", p.x, limits::kMaxCoordinate_m, "m");
    abs_at_most(field + "[1]", p.y, limits::kMaxCoordinate_m, "m");
  }
  void direction(const std::string& field, Vec2 d) const {
    point(field, d);
    if (std::hypot(d.x, d.y) < 1e-12) fail(field, "must be a non-zero vector");
  }
  // Names of one kind: valid and unique. `path` is the list ("bodies"), `i` the item.
  void name(const std::string& path, size_t i, const std::string& n,
            std::set<std::string>& seen) const {
    name(fmt::format("{}[{}].name", path, i), n, seen, path);
  }
  void name(const std::string& f, const std::string& n, std::set<std::string>& seen,
            const std::string& path = "") const {
    if (!is_valid_name(n)) fail(f, invalid_name_message(n));
    if (!seen.insert(n).second)
      fail(f, fmt::format("duplicate name '{}' in {}", n, path.empty() ? f : path));
  }
  void count(const std::string& field, size_t n) const {
    if (n > limits::kMaxItems)
      fail(field, fmt::format("{} items; a scene may have at most {}", n, limits::kMaxItems));
  }
  void points(const std::string& field, const std::map<std::string, Vec2>& pts) const {
    count(field, pts.size());
    for (const auto& [n, p] : pts) {
      if (!is_valid_name(n)) fail(field, "point " + invalid_name_message(n));
      point(field + "." + n, p);
    }
  }
  // A joint coordinate: an angle for a revolute joint, a length for a prismatic one.
  void coordinate(const std::string& field, const Joint* j, double v) const {
    if (j && j->type == JointType::Prismatic)
      abs_at_most(field, v, limits::kMaxCoordinate_m, "m");
    else
      abs_at_most(field, v, limits::kMaxAngle_rad, "rad");
  }
};

// A joint torque's profile (models/load_profile.hpp): a revolute `of` joint, bounded counts,
// finite coefficients or rows, and an applied load |value|·max|τ| within limits::kMaxForce.
// `value_key` names the amplitude's key (torque_Nm, force_N), `unit` the load's unit.
void check_profile(const Checker& c, const std::string& f, const LoadProfile& p, double value,
                   const std::string& value_key, const char* unit) {
  const std::string pf = f + ".profile";
  const Joint* of = c.s.find_joint(p.of);
  if (!of) c.fail(pf + ".of", "unknown joint '" + printable(p.of) + "'");
  if (of->type != JointType::Revolute)
    c.fail(pf + ".of", "a profile reads the angle of a revolute joint ('" + p.of + "' is prismatic)");
  if (!p.is_table()) {
    if (p.a.size() > limits::kMaxProfileHarmonics || p.b.size() > limits::kMaxProfileHarmonics)
      c.fail(pf + ".fourier", fmt::format("at most {} harmonics", limits::kMaxProfileHarmonics));
    c.abs_at_most(pf + ".fourier.a0", p.a0, limits::kMaxForce, unit);
    for (size_t k = 0; k < p.a.size(); ++k)
      c.abs_at_most(pf + fmt::format(".fourier.a[{}]", k), p.a[k], limits::kMaxForce, unit);
    for (size_t k = 0; k < p.b.size(); ++k)
      c.abs_at_most(pf + fmt::format(".fourier.b[{}]", k), p.b[k], limits::kMaxForce, unit);
  } else {
    const size_t n = p.table_theta_rad.size();
    if (n < limits::kMinProfileRows || n > limits::kMaxProfileRows || p.table_value.size() != n ||
        p.table_d2.size() != n)
      c.fail(pf + ".table_deg", fmt::format("a periodic table takes {} to {} rows (got {})",
                                            limits::kMinProfileRows, limits::kMaxProfileRows, n));
    constexpr double kPi = 3.14159265358979323846, h_min = limits::kMinProfileSpacing_deg * kPi / 180;
    for (size_t i = 0; i < n; ++i) {
      const std::string row = pf + fmt::format(".table_deg[{}]", i);
      c.abs_at_most(row + "[1]", p.table_value[i], limits::kMaxForce, unit);
      const double x = p.table_theta_rad[i];
      const double next = i + 1 < n ? p.table_theta_rad[i + 1] : p.table_theta_rad[0] + 2 * kPi;
      if (!std::isfinite(x) || std::abs(x) > 2 * kPi + 1e-12 || !(next - x >= h_min * (1 - 1e-9)))
        c.fail(row + "[0]", fmt::format("table angles must lie in [−360°, 360°] and increase by at least {:g}° "
                                        "within one turn",
                                        limits::kMinProfileSpacing_deg));
    }
  }
  const double bound = std::abs(value) * calc_profile_bound(p);
  if (!(bound <= limits::kMaxForce))
    c.fail(f + "." + value_key,
           fmt::format("the profiled load can reach {:g} {} (|amplitude {:g}| × profile bound {:g}); at most {:g}",
                       bound, unit, value, calc_profile_bound(p), limits::kMaxForce));
}

// Names that become reduced-table columns (reduced/extract.cpp) must give each column one
// meaning; found here so the refusal names the scene's field and line, not a bare "duplicate
// column" from the extraction (issue #23).
// - The reduced model's own reaction lines are constraint forces named R_<joint>_gx and
//   R_<joint>_gy (reduced/joint_outputs.hpp, internal_request_name): a scene's force may not
//   take such a name.
// - Columns named from two names, rx_<force>_<joint>, wx_<force>_<body> and
//   Qxpf_<force>_<point force>, meet when underscores shift between the two: force 'a_b' with
//   joint 'c' and force 'a' with joint 'b_c' both make rx_a_b_c.
void check_table_column_names(const Checker& c, const Scene& s) {
  const auto& cf = s.outputs.constraint_forces;
  std::vector<std::pair<std::string, std::string>> forces;  // name, field that gives it
  for (size_t i = 0; i < cf.size(); ++i) {
    const std::string field = fmt::format("outputs.constraint_forces[{}].name", i);
    // validate judges quantities by name: a force named like the speed would take its verdict
    // (a wrong knee force named 'qdot' was judged on the speed's error).
    for (const char* q : {"qdot", "mean_qdot", "q", "qddot", "energy", "work"})
      if (cf[i].name == q)
        c.fail(field, fmt::format("'{}' is reserved: validate and the time series use it for the motion itself; "
                                  "choose another name",
                                  q));
    for (const auto& j : s.joints)
      for (const char* axis : {"_gx", "_gy"})
        if (cf[i].name == "R_" + j.name + axis)
          c.fail(field, fmt::format("'{}' is reserved: the reduced model names its own reaction lines R_<joint>_gx "
                                    "and R_<joint>_gy; choose another name",
                                    printable(cf[i].name)));
    forces.push_back({cf[i].name, field});
  }
  if (!s.outputs.reactions.empty())  // the reaction lines the reduced model adds (a superset)
    for (const auto& j : s.joints)
      for (const char* axis : {"_gx", "_gy"}) forces.push_back({"R_" + j.name + axis, "outputs.reactions"});
  std::map<std::string, std::string> made;  // column → what makes it
  auto add = [&](const std::string& prefix, const std::pair<std::string, std::string>& force, const char* kind,
                 const std::string& other) {
    const std::string column = prefix + force.first + "_" + other;
    const std::string what = fmt::format("constraint force '{}' with {} '{}'", force.first, kind, other);
    const auto [it, inserted] = made.emplace(column, what);
    if (!inserted && it->second != what)
      c.fail(force.second, fmt::format("{} and {} both make the reduced table's column '{}'; rename one of them so "
                                       "each column has one meaning",
                                       it->second, what, printable(column)));
  };
  for (const auto& f : forces) {
    for (const auto& j : s.joints) add("rx_", f, "joint", j.name);
    for (const auto& r : s.resistances) add("wx_", f, "body", r.body);
    for (const auto& pf : s.point_forces) add("Qxpf_", f, "point force", pf.name);
  }
}

bool is_body_or_ground(const Scene& s, const std::string& n) { return n == kGround || s.find_body(n); }

void check_joint_ref(const Checker& c, const std::string& field, const std::string& j) {
  if (!c.s.find_joint(j)) c.fail(field, "unknown joint '" + printable(j) + "'");
}

// The scene's name and texts, and the size of every list before any list is walked.
void check_header_and_counts(const Checker& c, const Scene& s) {
  if (!is_valid_name(s.name)) c.fail("name", invalid_name_message(s.name));
  if (s.description.size() > limits::kMaxTextLength)
    c.fail("description", fmt::format("longer than {} characters", limits::kMaxTextLength));
  if (s.validation.note.size() > limits::kMaxTextLength)
    c.fail("validation.note", fmt::format("longer than {} characters", limits::kMaxTextLength));
  c.count("bodies", s.bodies.size());
  c.count("joints", s.joints.size());
  c.count("loops", s.loops.size());
  c.count("gears", s.gears.size());
  c.count("loads",
          s.joint_torques.size() + s.resistances.size() + s.springs.size() + s.motors.size() +
              s.point_forces.size());
  c.count("outputs.constraint_forces", s.outputs.constraint_forces.size());
  c.count("outputs.bodies", s.outputs.bodies.size());
  c.count("validation.thresholds", s.validation.thresholds.size());
  c.points("ground_points", s.ground_points);
}

// Names first, so that the fields checked after them can name items by name: valid, and unique
// within each kind.
void check_names(const Checker& c, const Scene& s) {
  std::set<std::string> names;
  for (size_t i = 0; i < s.bodies.size(); ++i) {
    if (s.bodies[i].name == kGround)
      c.fail(fmt::format("bodies[{}].name", i), "'ground' is reserved");
    c.name("bodies", i, s.bodies[i].name, names);
  }
  names.clear();
  for (size_t i = 0; i < s.joints.size(); ++i) c.name("joints", i, s.joints[i].name, names);
  names.clear();
  for (size_t i = 0; i < s.loops.size(); ++i) c.name("loops", i, s.loops[i].name, names);
  names.clear();
  for (size_t i = 0; i < s.gears.size(); ++i) c.name("gears", i, s.gears[i].name, names);
  names.clear();
  {  // loads: one kind in one list, kept here by type, so no list index in the field
    std::vector<std::string> load_names;
    for (const auto& t : s.joint_torques) load_names.push_back(t.name);
    for (const auto& r : s.resistances) load_names.push_back(r.name);
    for (const auto& sp : s.springs) load_names.push_back(sp.name);
    for (const auto& m : s.motors) load_names.push_back(m.name);
    for (const auto& pf : s.point_forces) load_names.push_back(pf.name);
    for (const auto& n : load_names) c.name("loads", n, names);
  }
  names.clear();
  for (size_t i = 0; i < s.outputs.constraint_forces.size(); ++i)
    c.name("outputs.constraint_forces", i, s.outputs.constraint_forces[i].name, names);
}

void check_bodies(const Checker& c, const Scene& s) {
  for (const auto& b : s.bodies) {
    const std::string f = "bodies." + b.name;
    c.in_range(f + ".mass_kg", b.mass_kg, limits::kMinMass_kg, limits::kMaxMass_kg, "kg");
    c.in_range(f + ".inertia_kgm2", b.inertia_kgm2, limits::kMinInertia_kgm2,
               limits::kMaxInertia_kgm2, "kg·m²");
    c.point(f + ".com_m", b.com_m);
    c.points(f + ".points", b.points);
  }
  if (s.bodies.empty()) c.fail("bodies", "the scene has no bodies");
}

// Tree: every body is the child of exactly one joint, and walking parents reaches ground.
void check_joint_tree(const Checker& c, const Scene& s) {
  std::map<std::string, std::string> parent_of;
  for (const auto& j : s.joints) {
    const std::string f = "joints." + j.name;
    if (!is_body_or_ground(s, j.parent))
      c.fail(f + ".parent", "unknown body '" + printable(j.parent) + "'");
    if (!s.find_body(j.child)) c.fail(f + ".child", "unknown body '" + printable(j.child) + "'");
    if (j.parent == j.child) c.fail(f + ".child", "a joint cannot join a body to itself");
    if (parent_of.count(j.child))
      c.fail(f + ".child", "body '" + j.child +
                               "' is already the child of another joint; "
                               "close loops with 'loops', not with a second joint");
    parent_of[j.child] = j.parent;
    c.point(f + ".parent_point", j.parent_point);
    c.point(f + ".child_point", j.child_point);
    if (j.type == JointType::Prismatic) {
      c.direction(f + ".axis", j.axis);
      c.coordinate(f + ".guess_m", &j, j.guess);
    } else {
      c.coordinate(f + ".offset", &j, j.offset_rad);  // offset_deg/guess_deg: checked by the reader
      c.coordinate(f + ".guess", &j, j.guess);
    }
  }
  for (const auto& b : s.bodies) {
    if (!parent_of.count(b.name))
      c.fail("bodies." + b.name, "body is not attached by any joint (every body needs one)");
    std::string cur = b.name;
    for (size_t hops = 0; cur != kGround; ++hops) {
      if (hops > s.bodies.size()) c.fail("joints", "joints form a cycle through '" + b.name + "'");
      cur = parent_of[cur];
    }
  }
}

void check_loops(const Checker& c, const Scene& s) {
  for (const auto& l : s.loops) {
    const std::string f = "loops." + l.name;
    if (!is_body_or_ground(s, l.body_a))
      c.fail(f + ".body_a", "unknown body '" + printable(l.body_a) + "'");
    if (!is_body_or_ground(s, l.body_b))
      c.fail(f + ".body_b", "unknown body '" + printable(l.body_b) + "'");
    if (l.body_a == l.body_b) c.fail(f, "a loop must join two different bodies");
    c.point(f + ".point_a", l.point_a);
    c.point(f + ".point_b", l.point_b);
  }
}

void check_gears(const Checker& c, const Scene& s) {
  for (const auto& g : s.gears) {
    const std::string f = "gears." + g.name;
    const Joint* a = s.find_joint(g.driver);
    const Joint* b = s.find_joint(g.driven);
    if (!a) c.fail(f + ".driver", "unknown joint '" + printable(g.driver) + "'");
    if (!b) c.fail(f + ".driven", "unknown joint '" + printable(g.driven) + "'");
    // A joint geared to itself is no constraint at all (rate = r·rate is 0 = 0 for r = 1, or
    // freezes the joint otherwise), yet it would be counted as one in the mobility below.
    if (a == b)
      c.fail(f + ".driven", "a gear must couple two different joints (driver and driven are both '" +
                                g.driver + "')");
    if (a->type != JointType::Revolute || b->type != JointType::Revolute)
      c.fail(f, "gears couple two revolute joints");
    if (!std::isfinite(g.ratio) || std::abs(g.ratio) < limits::kMinGearRatio ||
        std::abs(g.ratio) > limits::kMaxGearRatio)
      c.fail(f + ".ratio", fmt::format("must be finite with |ratio| in [{:g}, {:g}] (got {:g})",
                                       limits::kMinGearRatio, limits::kMaxGearRatio, g.ratio));
  }
}

// Mobility (Grübler for planar joints): each joint adds one coordinate, each loop removes two,
// each gear one; and the independent coordinate is one of the joints.
void check_mobility(const Checker& c, const Scene& s) {
  const int dof = static_cast<int>(s.joints.size()) - 2 * static_cast<int>(s.loops.size()) -
                  static_cast<int>(s.gears.size());
  if (dof != 1)
    c.fail("joints", fmt::format("the mechanism has {} degrees of freedom ({} joints, {} loops, "
                                 "{} gears); rdyn needs exactly 1",
                                 dof, s.joints.size(), s.loops.size(), s.gears.size()));
  if (!s.find_joint(s.independent))
    c.fail("independent", "unknown joint '" + printable(s.independent) + "'");
}

void check_joint_torques(const Checker& c, const Scene& s) {
  for (const auto& t : s.joint_torques) {
    const std::string f = "loads." + t.name;
    check_joint_ref(c, f + ".joint", t.joint);
    const bool prismatic = s.find_joint(t.joint)->type == JointType::Prismatic;
    c.abs_at_most(f + (prismatic ? ".force_N" : ".torque_Nm"), t.value, limits::kMaxForce,
                  prismatic ? "N" : "N·m");
    if (t.active_when) check_joint_ref(c, f + ".active_when.joint", t.active_when->joint);
    if (t.profile)
      check_profile(c, f, *t.profile, t.value, prismatic ? "force_N" : "torque_Nm", prismatic ? "N" : "N·m");
  }
}

void check_point_forces(const Checker& c, const Scene& s) {
  for (const auto& pf : s.point_forces) {
    // Coincident points in the assembled configuration (no direction) are the engine's check:
    // only an assembly knows where the points are (engine/full_model.cpp).
    const std::string f = "loads." + pf.name;
    if (!is_body_or_ground(s, pf.body_a)) c.fail(f + ".body_a", "unknown body '" + printable(pf.body_a) + "'");
    if (!is_body_or_ground(s, pf.body_b)) c.fail(f + ".body_b", "unknown body '" + printable(pf.body_b) + "'");
    if (pf.body_a == pf.body_b)
      c.fail(f + ".body_b", "a point force between two points of one body ('" + pf.body_a +
                                "') keeps its length and does nothing: give two different bodies");
    c.point(f + ".point_a", pf.point_a);
    c.point(f + ".point_b", pf.point_b);
    c.abs_at_most(f + ".force_N", pf.value, limits::kMaxForce, "N");
    if (pf.active_when) check_joint_ref(c, f + ".active_when.joint", pf.active_when->joint);
    if (pf.profile) check_profile(c, f, *pf.profile, pf.value, "force_N", "N");
  }
}

void check_resistances(const Checker& c, const Scene& s) {
  for (const auto& r : s.resistances) {
    const std::string f = "loads." + r.name;
    const Body* b = s.find_body(r.body);
    if (!b) c.fail(f + ".body", "unknown body '" + printable(r.body) + "'");
    const double max_c = b->inertia_kgm2 / limits::kMinResistanceTimeConstant_s;
    if (!std::isfinite(r.coefficient) || r.coefficient < 0.0 || r.coefficient > max_c)
      c.fail(f + ".coefficient",
             fmt::format(
                 "must be in [0, {:g}] = inertia of '{}' / {:g} s, so that the resistance alone "
                 "cannot change its speed faster than that time constant (got {:g})",
                 max_c, b->name, limits::kMinResistanceTimeConstant_s, r.coefficient));
  }
}

void check_springs(const Checker& c, const Scene& s) {
  for (const auto& sp : s.springs) {
    const std::string f = "loads." + sp.name;
    if (!is_body_or_ground(s, sp.body_a))
      c.fail(f + ".body_a", "unknown body '" + printable(sp.body_a) + "'");
    if (!is_body_or_ground(s, sp.body_b))
      c.fail(f + ".body_b", "unknown body '" + printable(sp.body_b) + "'");
    c.point(f + ".point_a", sp.point_a);
    c.point(f + ".point_b", sp.point_b);
    c.in_range(f + ".stiffness_N_per_m", sp.stiffness_N_per_m, 0.0, limits::kMaxStiffness_N_per_m,
               "N/m");
    c.in_range(f + ".rest_length_m", sp.rest_length_m, 0.0, limits::kMaxCoordinate_m, "m");
  }
}

void check_motors(const Checker& c, const Scene& s) {
  for (const auto& m : s.motors) {
    const std::string f = "loads." + m.name;
    check_joint_ref(c, f + ".joint", m.joint);
    const bool prismatic = s.find_joint(m.joint)->type == JointType::Prismatic;
    const std::string speed = f + (prismatic ? ".no_load_speed_m_s" : ".no_load_speed_rad_s");
    c.abs_at_most(f + (prismatic ? ".stall_force_N" : ".stall_torque_Nm"), m.stall_torque,
                  limits::kMaxForce, prismatic ? "N" : "N·m");
    if (!std::isfinite(m.no_load_speed) || std::abs(m.no_load_speed) < limits::kMinMotorSpeed ||
        std::abs(m.no_load_speed) > limits::kMaxRate)
      c.fail(speed, fmt::format("must be finite with |value| in [{:g}, {:g}] (got {:g})",
                                limits::kMinMotorSpeed, limits::kMaxRate, m.no_load_speed));
    // τ = stall·(1 − rate/no_load_speed) drives the rate toward no_load_speed only when both have
    // the same sign; with opposite signs the torque grows with the speed it produces (a runaway).
    if (m.stall_torque * m.no_load_speed < 0.0)
      c.fail(speed,
             fmt::format(
                 "has the opposite sign of the stall torque ({:g} vs {:g}): such a motor pushes "
                 "harder the faster it turns and runs away; give both the sign of the "
                 "direction it drives",
                 m.no_load_speed, m.stall_torque));
  }
}

// outputs: the constraint forces asked for, the reduced-table columns they make, and the bodies
// whose motion is written.
void check_outputs(const Checker& c, const Scene& s) {
  for (size_t i = 0; i < s.outputs.constraint_forces.size(); ++i) {
    const auto& cf = s.outputs.constraint_forces[i];
    const std::string f = "outputs.constraint_forces." + cf.name;
    const Joint* j = s.find_joint(cf.joint);
    if (!j) c.fail(f + ".joint", "unknown joint '" + printable(cf.joint) + "'");
    if (j->type != JointType::Revolute) c.fail(f, "constraint forces are offered on revolute joints");
    // The independent joint too: its pin is the prescribed (or free) coordinate and the
    // constraint actuator's sliders follow it (engine/full_model.cpp).
    c.direction(f + ".direction", cf.direction);
  }
  check_table_column_names(c, s);
  std::set<std::string> seen;
  for (size_t i = 0; i < s.outputs.bodies.size(); ++i) {
    const std::string& b = s.outputs.bodies[i];
    const std::string f = fmt::format("outputs.bodies[{}]", i);
    if (!s.find_body(b)) c.fail(f, "unknown body '" + printable(b) + "'");
    if (!seen.insert(b).second) c.fail(f, "body '" + b + "' listed twice");
  }
}

// Gravity, the initial state and the independent coordinate's declared range.
void check_initial(const Checker& c, const Scene& s) {
  const Joint* independent = s.find_joint(s.independent);
  c.abs_at_most("gravity.g_m_s2[0]", s.gravity.g_m_s2.x, limits::kMaxGravity_m_s2, "m/s²");
  c.abs_at_most("gravity.g_m_s2[1]", s.gravity.g_m_s2.y, limits::kMaxGravity_m_s2, "m/s²");
  c.coordinate("initial.q", independent, s.initial.q);
  c.abs_at_most("initial.qdot", s.initial.qdot, limits::kMaxRate, "rad/s or m/s");
  if (const auto& r = s.independent_range) {
    const std::string f = "independent_range";
    c.coordinate(f + "[0]", independent, r->min);
    c.coordinate(f + "[1]", independent, r->max);
    if (!(r->min < r->max)) c.fail(f, fmt::format("needs min < max (got [{:g}, {:g}])", r->min, r->max));
    if (!(s.initial.q >= r->min && s.initial.q <= r->max))
      c.fail("initial.q", fmt::format("{:.9g} lies outside independent_range [{:.9g}, {:.9g}] (rad or m)", s.initial.q, r->min, r->max));
  }
}

void check_simulation(const Checker& c, const Scene& s) {
  const auto& sim = s.simulation;
  if (!(sim.duration_s > 0.0 && sim.duration_s <= limits::kMaxDuration_s))
    c.fail("simulation.duration_s",
           fmt::format("must be in (0, {:g}] s (got {:g})", limits::kMaxDuration_s, sim.duration_s));
  c.in_range("simulation.output_interval_s", sim.output_interval_s, limits::kMinOutputInterval_s,
             sim.duration_s, "s");
  const double longest = std::max(sim.duration_s, s.validation.duration_s);
  if (longest / sim.output_interval_s > limits::kMaxOutputRows)
    c.fail("simulation.output_interval_s",
           fmt::format("{:g} s over {:g} s gives {:g} output rows; at most {:g}",
                       sim.output_interval_s, longest, longest / sim.output_interval_s,
                       limits::kMaxOutputRows));
  c.in_range("simulation.tolerance", sim.tolerance, limits::kMinTolerance, limits::kMaxTolerance,
             "");
}

// validation: its durations and tolerance, the thresholds' quantities and grids, and the
// calibration's operating point.
void check_validation(const Checker& c, const Scene& s) {
  const auto& v = s.validation;
  c.in_range("validation.duration_s", v.duration_s, 0.0, limits::kMaxDuration_s,
             "s (0: simulation.duration_s)");
  c.in_range("validation.reference_tolerance", v.reference_tolerance, limits::kMinTolerance,
             limits::kMaxReferenceTolerance, "");
  for (size_t i = 0; i < v.thresholds.size(); ++i) {
    const auto& th = v.thresholds[i];
    const std::string f = fmt::format("validation.thresholds[{}]", i);
    bool known = th.quantity == "qdot" || th.quantity == "mean_qdot";
    for (const auto& cf : s.outputs.constraint_forces) known |= cf.name == th.quantity;
    for (const auto& col : joint_output_names(s)) known |= col == th.quantity;
    if (!known)
      c.fail(f + ".quantity",
             fmt::format("'{}' is neither qdot, mean_qdot, the name of a requested constraint force nor a requested "
                         "joint output column (q_<joint>, qdot_<joint>, qddot_<joint>, R_<joint>_x …, shaking_x …)",
                         printable(th.quantity)));
    if (!th.interpolation.empty() && !is_valid_name(th.interpolation))
      c.fail(f + ".interpolation",
             fmt::format("'{}' is not a valid interpolation name", printable(th.interpolation)));
    if (!(th.max_error > 0.0 && th.max_error <= 1.0))
      c.fail(f + ".max_error", fmt::format("must be in (0, 1] (a fraction; got {:g})", th.max_error));
    c.in_range(f + ".grid_deg", th.grid_deg, limits::kMinGrid_deg, limits::kMaxGrid_deg, "degrees");
    // The table is periodic over one turn: the grid must divide 360° into whole steps.
    const double steps = 360.0 / th.grid_deg;
    if (std::abs(steps - std::round(steps)) > 1e-9 * steps)
      c.fail(f + ".grid_deg",
             fmt::format("{:g}° does not divide 360° into whole steps", th.grid_deg));
  }
  if (v.calibrate_cadence_Hz != 0.0 || v.calibrate_power_W != 0.0) {
    if (!(v.calibrate_cadence_Hz > 0.0 && v.calibrate_cadence_Hz <= limits::kMaxCadence_Hz))
      c.fail("validation.calibrate.cadence_Hz",
             fmt::format("must be in (0, {:g}] Hz (got {:g})", limits::kMaxCadence_Hz,
                         v.calibrate_cadence_Hz));
    if (!(v.calibrate_power_W >= 0.0 && v.calibrate_power_W <= limits::kMaxPower_W))
      c.fail("validation.calibrate.power_W", fmt::format("must be in (0, {:g}] W (got {:g})",
                                                         limits::kMaxPower_W, v.calibrate_power_W));
    c.in_range("validation.calibrate.grid_deg", v.calibrate_grid_deg, limits::kMinGrid_deg, limits::kMaxGrid_deg,
               "degrees");
    const double steps = 360.0 / v.calibrate_grid_deg;
    if (std::abs(steps - std::round(steps)) > 1e-9 * steps)
      c.fail("validation.calibrate.grid_deg",
             fmt::format("{:g}° does not divide 360° into whole steps", v.calibrate_grid_deg));
  }
}

}  // namespace

// Each stage throws SceneError on its first violation; the order of the stages is the order in
// which a scene's errors are reported (names before the fields that name items by name).
void check_scene(const Scene& s) {
  const Checker c{s};
  check_header_and_counts(c, s);
  check_names(c, s);
  check_bodies(c, s);
  check_joint_tree(c, s);
  check_loops(c, s);
  check_gears(c, s);
  check_mobility(c, s);
  check_joint_torques(c, s);
  check_point_forces(c, s);
  check_resistances(c, s);
  check_springs(c, s);
  check_motors(c, s);
  check_outputs(c, s);
  check_initial(c, s);
  check_simulation(c, s);
  check_validation(c, s);
}

int dissipation_exponent(ResistanceLaw law) {
  return law == ResistanceLaw::Constant ? 1 : law == ResistanceLaw::Viscous ? 2 : 3;
}

std::optional<double> fixed_speed_ratio(const Scene& s, const std::string& body) {
  for (const auto& j : s.joints) {
    if (j.child != body || j.parent != kGround || j.type != JointType::Revolute) continue;
    if (j.name == s.independent) return 1.0;
    const Joint* ind = s.find_joint(s.independent);
    // Called before check_scene (to turn `dissipates` into a coefficient): names may be unknown.
    if (!ind || ind->parent != kGround) continue;
    for (const auto& g : s.gears) {
      // rate(driven) = ratio·rate(driver), written either way round (a motor driving the crank
      // at 0.04 is the crank driving the motor at 25).
      if (g.driven == j.name && g.driver == s.independent) return g.ratio;
      if (g.driver == j.name && g.driven == s.independent && g.ratio != 0) return 1.0 / g.ratio;
    }
  }
  return std::nullopt;
}

std::vector<std::string> joint_output_names(const Scene& s) {
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
    if (j && j->type == JointType::Prismatic) {
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

}  // namespace rdyn::models
