#include "models/scene_yaml.hpp"

#include <fmt/format.h>
#include <sys/stat.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "models/bicycle_leg.hpp"
#include "models/scene_yaml_study.hpp"
#include "models/yaml_fields.hpp"

namespace rdyn::models {

using namespace yaml;
namespace {
ResistanceLaw read_law(const Fields& f, const std::string& key) {
  const std::string v = f.str(key);
  if (v == "constant") return ResistanceLaw::Constant;
  if (v == "viscous") return ResistanceLaw::Viscous;
  if (v == "quadratic") return ResistanceLaw::Quadratic;
  f.fail(key, "expected constant, viscous or quadratic");
}

void read_bicycle_leg(const Fields& f, Scene& s) {
  BicycleLegParams p;
  if (f.has("subject")) {
    Fields sub(f.raw("subject"), f.join("subject"), f.ctx(), {"height_m", "mass_kg", "sex"});
    p.height_m = sub.num_or("height_m", p.height_m);
    p.mass_kg = sub.num_or("mass_kg", p.mass_kg);
    p.sex = sub.str_or("sex", p.sex);
  }
  const double legs = f.num_or("legs", p.legs);
  if (legs != 1.0 && legs != 2.0) f.fail("legs", "must be 1 or 2");
  p.legs = static_cast<int>(legs);
  p.crank_length_m = f.num_or("crank_length_m", p.crank_length_m);
  p.crank_mass_kg = f.num_or("crank_mass_kg", p.crank_mass_kg);
  p.seat_tube_angle_deg = f.num_or("seat_tube_angle_deg", p.seat_tube_angle_deg);
  p.knee_flexion_at_extension_deg =
      f.num_or("knee_flexion_at_extension_deg", p.knee_flexion_at_extension_deg);
  p.ankle_angle_deg = f.num_or("ankle_angle_deg", p.ankle_angle_deg);
  p.pedal_stack_m = f.num_or("pedal_stack_m", p.pedal_stack_m);
  p.hip_torque_Nm = f.num_or("hip_torque_Nm", p.hip_torque_Nm);
  if (f.has("flywheel")) {
    Fields fw(f.raw("flywheel"), f.join("flywheel"), f.ctx(),
              {"gear_ratio", "inertia_kgm2", "mass_kg", "bike_mass_kg", "wheel_radius_m",
               "wheel_inertia_kgm2"});
    p.gear_ratio = fw.num_or("gear_ratio", p.gear_ratio);
    if (fw.has("inertia_kgm2")) p.flywheel_inertia_kgm2 = fw.num("inertia_kgm2");
    p.flywheel_mass_kg = fw.num_or("mass_kg", p.flywheel_mass_kg);
    p.bike_mass_kg = fw.num_or("bike_mass_kg", p.bike_mass_kg);
    p.wheel_radius_m = fw.num_or("wheel_radius_m", p.wheel_radius_m);
    p.wheel_inertia_kgm2 = fw.num_or("wheel_inertia_kgm2", p.wheel_inertia_kgm2);
  }
  if (f.has("resistance")) {
    Fields r(f.raw("resistance"), f.join("resistance"), f.ctx(), {"law", "power_W", "cadence_Hz"});
    if (r.has("law")) p.resistance_law = read_law(r, "law");
    p.resistance_power_W = r.num_or("power_W", p.resistance_power_W);
    p.resistance_cadence_Hz = r.num_or("cadence_Hz", p.resistance_cadence_Hz);
  }
  make_bicycle_leg(p, s);
}

// A mapping name: [x, y] of points (ground_points, a body's points).
void read_named_points(const Fields& f, const std::string& key, std::map<std::string, Vec2>& out) {
  const YAML::Node pts = f.raw(key);
  if (!pts.IsMap()) f.fail(key, "expected a mapping name: [x, y]");
  for (const auto& kv : pts) {
    if (!kv.first.IsScalar()) f.fail(key, "a point's name must be plain text");
    out[kv.first.as<std::string>()] = f.to_vec2(kv.second, f.join(key + "." + kv.first.as<std::string>()));
  }
}

Body read_body(const Fields& f, const Scene& s) {
  Body b;
  b.name = f.name("name");
  b.mass_kg = f.num("mass_kg");  // ranges: check_scene
  b.com_m = f.has("com_m") ? f.vec2("com_m") : Vec2{};
  b.inertia_kgm2 = f.num("inertia_kgm2");
  if (s.find_body(b.name) || b.name == kGround) f.fail("name", "duplicate body name '" + b.name + "'");
  if (f.has("points")) read_named_points(f, "points", b.points);
  return b;
}

Joint read_joint(const Fields& f, const Scene& s) {
  Joint j;
  j.name = f.name("name");
  const std::string type = f.str("type");
  if (type == "revolute")
    j.type = JointType::Revolute;
  else if (type == "prismatic")
    j.type = JointType::Prismatic;
  else
    f.fail("type", "expected revolute or prismatic");
  j.parent = f.str("parent");
  j.child = f.str("child");
  if (j.parent != kGround && !s.find_body(j.parent)) f.fail("parent", "unknown body '" + j.parent + "'");
  if (!s.find_body(j.child)) f.fail("child", "unknown body '" + j.child + "'");
  j.parent_point = f.has("parent_point") ? read_point(f, "parent_point", j.parent, s) : Vec2{};
  j.child_point = f.has("child_point") ? read_point(f, "child_point", j.child, s) : Vec2{};
  if (j.type == JointType::Prismatic) {
    j.axis = f.has("axis") ? f.vec2("axis") : Vec2{1, 0};
    const double len = std::hypot(j.axis.x, j.axis.y);
    if (len < 1e-12) f.fail("axis", "must be a non-zero vector");
    j.axis = unit_vector(j.axis, len);
    if (f.has("offset_deg") || f.has("guess_deg") || f.has("offset_rad") || f.has("guess_rad"))
      f.fail("type", "prismatic joints take guess_m, not angles");
    j.guess = f.num_or("guess_m", 0.0);
    return j;
  }
  if (f.has("axis") || f.has("guess_m")) f.fail("type", "revolute joints take guess_deg and no axis");
  // Degrees, or radians (what scene_to_yaml writes: x·π/180 need not round back to the same double).
  const double max_deg = limits::kMaxAngle_rad * 180.0 / kPi;
  auto angle = [&](const std::string& name) {
    if (f.has(name + "_deg") && f.has(name + "_rad"))
      f.fail(name + "_rad", fmt::format("give {0}_deg or {0}_rad, not both", name));
    if (f.has(name + "_rad")) return f.num_abs_max(name + "_rad", 0.0, limits::kMaxAngle_rad, "rad");
    return f.num_abs_max(name + "_deg", 0.0, max_deg, "degrees") * kPi / 180.0;
  };
  j.offset_rad = angle("offset");
  j.guess = angle("guess");
  return j;
}

// The joints a loop closes over: those on exactly one of the two tree paths from body_a and
// body_b down to ground (only they can tell its branches apart).
std::vector<std::string> joints_of_loop(const Scene& s, const Loop& l) {
  auto path_to_ground = [&](std::string body) {
    std::vector<std::string> joints;
    for (size_t guard = 0; guard <= s.joints.size() && body != "ground"; ++guard) {
      const auto it = std::find_if(s.joints.begin(), s.joints.end(), [&](const Joint& jt) { return jt.child == body; });
      if (it == s.joints.end()) break;
      joints.push_back(it->name);
      body = it->parent;
    }
    return joints;
  };
  const auto pa = path_to_ground(l.body_a), pb = path_to_ground(l.body_b);
  std::vector<std::string> on_loop;
  for (const auto& j : pa)
    if (std::find(pb.begin(), pb.end(), j) == pb.end()) on_loop.push_back(j);
  for (const auto& j : pb)
    if (std::find(pa.begin(), pa.end(), j) == pa.end()) on_loop.push_back(j);
  return on_loop;
}

// A loop's `branch`: {joint, sign: positive|negative} (or +1 / -1).
BranchSign read_branch(const Fields& b, const Fields& top, const Scene& s, const Loop& l) {
  BranchSign br{b.str("joint"), +1};
  if (!s.find_joint(br.joint)) b.fail("joint", "unknown joint '" + br.joint + "'");
  if (br.joint == top.str_or("independent", ""))
    b.fail("joint", "the independent coordinate is set by `initial`, not by assembly: name another joint");
  const auto on_loop = joints_of_loop(s, l);
  if (std::find(on_loop.begin(), on_loop.end(), br.joint) == on_loop.end()) {
    std::string list;
    for (const auto& j : on_loop) list += (list.empty() ? "" : ", ") + j;
    b.fail("joint", fmt::format("'{}' is not a joint of loop '{}' (its joints: {}): only a joint the loop closes "
                                "over can pick its branch",
                                br.joint, l.name, list));
  }
  const std::string sign = b.str("sign");
  if (sign == "positive" || sign == "+1" || sign == "1") br.sign = +1;
  else if (sign == "negative" || sign == "-1") br.sign = -1;
  else b.fail("sign", "expected positive or negative (or +1, -1)");
  return br;
}

Loop read_loop(const Fields& f, const Fields& top, Scene& s) {
  Loop l;
  l.name = f.name("name");
  s.key_lines["loops." + l.name] = f.line();  // the engine's "cannot close" names the loop's line
  l.body_a = f.str("body_a");
  l.body_b = f.str("body_b");
  l.point_a = read_point(f, "point_a", l.body_a, s);
  l.point_b = read_point(f, "point_b", l.body_b, s);
  if (f.has("branch")) {
    note_key(s, top.ctx(), "loops." + l.name + ".branch", f.raw("branch"));
    l.branch = read_branch(Fields(f.raw("branch"), f.join("branch"), top.ctx(), {"joint", "sign"}), top, s, l);
  }
  return l;
}

// The mechanism: ground points, bodies, joints (tree), loops, gears, the independent joint.
void read_mechanism(const Fields& top, Scene& s) {
  if (top.has("ground_points")) read_named_points(top, "ground_points", s.ground_points);
  for_each_item(top, "bodies", [&](const YAML::Node& n, const std::string& path) {
    s.bodies.push_back(read_body(Fields(n, path, top.ctx(), {"name", "mass_kg", "com_m", "inertia_kgm2", "points"}), s));
  });
  for_each_item(top, "joints", [&](const YAML::Node& n, const std::string& path) {
    s.joints.push_back(read_joint(Fields(n, path, top.ctx(),
                                         {"name", "type", "parent", "child", "parent_point", "child_point", "axis",
                                          "offset_deg", "guess_deg", "guess_m", "offset_rad", "guess_rad"}),
                                  s));
  });
  for_each_item(top, "loops", [&](const YAML::Node& n, const std::string& path) {
    s.loops.push_back(read_loop(Fields(n, path, top.ctx(), {"name", "body_a", "point_a", "body_b", "point_b", "branch"}),
                                top, s));
  });
  for_each_item(top, "gears", [&](const YAML::Node& n, const std::string& path) {
    Fields f(n, path, top.ctx(), {"name", "driver", "driven", "ratio"});
    s.gears.push_back({f.name("name"), f.str("driver"), f.str("driven"), f.num("ratio")});
  });
  s.independent = top.str("independent");
  note_key(s, top.ctx(), "independent", top.raw("independent"));  // calibrate's and optimize's refusals name it
}

// independent_range: [min, max] in rad or m (as initial.q), or independent_range_deg for a
// revolute; values checked by check_scene.
void read_independent_range(const Fields& top, Scene& s) {
  const bool deg = top.has("independent_range_deg");
  if (!deg && !top.has("independent_range")) return;
  if (deg && top.has("independent_range"))
    top.fail("independent_range", "give independent_range or independent_range_deg, not both");
  const std::string key = deg ? "independent_range_deg" : "independent_range";
  const Joint* j = s.find_joint(s.independent);
  if (deg && j && j->type == JointType::Prismatic)
    top.fail(key, "a prismatic independent coordinate takes independent_range in metres, not degrees");
  const Vec2 v = top.vec2(key);
  const double k = deg ? kPi / 180.0 : 1.0;
  if (deg) {
    const double max_deg = limits::kMaxAngle_rad * 180.0 / kPi;
    if (std::abs(v.x) > max_deg || std::abs(v.y) > max_deg)
      top.fail(key, fmt::format("must be finite with |value| ≤ {:g} degrees", max_deg));
  }
  if (!(v.x < v.y)) top.fail(key, fmt::format("needs min < max (got [{:g}, {:g}])", v.x, v.y));  // here: the line
  s.independent_range = IndependentRange{v.x * k, v.y * k};
}

// A joint torque's profile: {of: joint, fourier: {a0, a: [...], b: [...]}} or
// {of: joint, table_deg: [[θ_deg, τ], ...]} (models/load_profile.hpp). Counts, finiteness and
// the order of the table's angles are checked here, where the line of each row is known;
// the joint and the load's range by check_scene.
LoadProfile read_profile(const Fields& parent, const std::string& key) {
  Fields p(parent.raw(key), parent.join(key), parent.ctx(), {"of", "fourier", "table_deg", "table_rad"});
  if (int(p.has("fourier")) + int(p.has("table_deg")) + int(p.has("table_rad")) != 1)
    p.fail("fourier",
           "give fourier: {a0, a, b} or table_deg: [[angle_deg, value], ...] (or table_rad), one of them");
  const std::string of = p.str("of");
  auto list = [&](const Fields& f, const std::string& k, size_t max, const char* what) {
    std::vector<double> v;
    if (!f.has(k)) return v;
    const YAML::Node seq = f.raw(k);
    if (!seq.IsSequence()) f.fail(k, "expected a list of numbers");
    if (seq.size() > max) f.fail(k, fmt::format("{} {}; at most {}", seq.size(), what, max));
    for (size_t i = 0; i < seq.size(); ++i) v.push_back(f.to_num(seq[i], f.join(k) + fmt::format("[{}]", i)));
    return v;
  };
  if (p.has("fourier")) {
    Fields f(p.raw("fourier"), p.join("fourier"), parent.ctx(), {"a0", "a", "b"});
    LoadProfile out;
    out.of = of;
    out.a0 = f.num_or("a0", 0.0);
    out.a = list(f, "a", limits::kMaxProfileHarmonics, "cosine coefficients");
    out.b = list(f, "b", limits::kMaxProfileHarmonics, "sine coefficients");
    return out;
  }
  // table_rad (what scene_to_yaml writes): the same rows in radians, checked in degrees.
  const bool rad = p.has("table_rad");
  const std::string table_key = rad ? "table_rad" : "table_deg";
  const YAML::Node rows = p.raw(table_key);
  const std::string field = p.join(table_key);
  if (!rows.IsSequence()) p.fail(table_key, "expected a list of [angle, value] rows");
  if (rows.size() < limits::kMinProfileRows || rows.size() > limits::kMaxProfileRows)
    p.fail(table_key, fmt::format("{} rows; a periodic table takes {} to {}", rows.size(),
                                    limits::kMinProfileRows, limits::kMaxProfileRows));
  std::vector<double> theta, value;
  for (size_t i = 0; i < rows.size(); ++i) {
    const std::string fi = field + fmt::format("[{}]", i);
    const Vec2 typed = p.to_vec2(rows[i], fi);
    const Vec2 row{rad ? typed.x * 180.0 / kPi : typed.x, typed.y};  // angle in degrees
    if (std::abs(row.x) > 360.0)
      p.fail_at(rows[i], fi + "[0]", fmt::format("angle {:g}° outside [−360°, 360°]", row.x));
    if (i > 0 && !(row.x - theta.back() * 180 / kPi >= limits::kMinProfileSpacing_deg))
      p.fail_at(rows[i], fi + "[0]",
                fmt::format("angles must increase by at least {:g}° from row to row (got {:g}° after {:g}°)",
                            limits::kMinProfileSpacing_deg, row.x, theta.back() * 180 / kPi));
    if (i > 0 && !(theta.front() * 180 / kPi + 360.0 - row.x >= limits::kMinProfileSpacing_deg))
      p.fail_at(rows[i], fi + "[0]",
                fmt::format("the table covers one turn: angles must stay below the first + 360° (got {:g}° "
                            "after a first angle of {:g}°)",
                            row.x, theta.front() * 180 / kPi));
    theta.push_back(rad ? typed.x : row.x * kPi / 180.0);
    value.push_back(row.y);
  }
  return make_table_profile(of, std::move(theta), std::move(value));
}

// A load's rate gate: active_when: {joint, rate: positive|negative} (the joint: check_scene).
RateGate read_rate_gate(const Fields& f) {
  Fields g(f.raw("active_when"), f.join("active_when"), f.ctx(), {"joint", "rate"});
  const std::string rate = g.str("rate");
  if (rate != "positive" && rate != "negative") g.fail("rate", "expected positive or negative");
  return RateGate{g.str("joint"), rate == "positive" ? +1 : -1};
}

struct PendingDissipation {
  size_t index;
  double power_W, cadence_Hz;
  int line;
};

// A load's value key must carry its joint's unit: a torque on a revolute joint, a force on a
// prismatic one. Both keys fill the same value, so a force_N on a revolute joint was read as
// N·m without a word (issue #23); refused here, where the key's line is known. An unknown
// joint is left to check_scene, which names it.
void check_unit_key(const Fields& f, const Scene& s, const std::string& joint, const std::string& torque_key,
                    const std::string& force_key) {
  const Joint* j = s.find_joint(joint);
  if (!j) return;
  const bool prismatic = j->type == JointType::Prismatic;
  const std::string& wrong = prismatic ? torque_key : force_key;
  if (f.has(wrong))
    f.fail(wrong, fmt::format("joint '{}' is {} ({}): give {} instead of {}", joint,
                              prismatic ? "prismatic" : "revolute",
                              prismatic ? "forces in N, speeds in m/s" : "torques in N·m, speeds in rad/s",
                              prismatic ? force_key : torque_key, wrong));
}

void read_loads(const Fields& top, Scene& s, std::vector<PendingDissipation>& pending) {
  std::set<std::string> names;
  for_each_item(top, "loads", [&](const YAML::Node& n, const std::string& path) {
    if (!n.IsMap() || !n["type"])
      throw SceneError(top.file(), line_of(n), path + ".type", "missing required field");
    if (!n["type"].IsScalar()) top.ctx().fail(n["type"], path + ".type", "expected a load type");
    const std::string type = n["type"].as<std::string>();
    if (n["name"] && (!n["name"].IsScalar() || !is_valid_name(n["name"].Scalar())))
      top.ctx().fail(
          n["name"], path + ".name",
          invalid_name_message(n["name"].IsScalar() ? n["name"].Scalar() : "(not text)"));
    const std::string name = n["name"] ? n["name"].Scalar() : fmt::format("load{}", names.size());
    if (!names.insert(name).second)
      throw SceneError(top.file(), line_of(n), path + ".name",
                       "duplicate load name '" + name + "'");
    s.key_lines["loads." + name] = line_of(n);  // refusals after loading (optimize's design) name the load's line
    if (type == "joint_torque") {
      Fields f(n, path, top.ctx(),
               {"type", "name", "joint", "torque_Nm", "force_N", "active_when", "profile"});
      JointTorque t{name, f.str("joint"), 0.0, std::nullopt, std::nullopt};
      if (f.has("torque_Nm") && f.has("force_N"))
        f.fail("torque_Nm", "give torque_Nm (revolute) or force_N (prismatic), not both");
      check_unit_key(f, s, t.joint, "torque_Nm", "force_N");
      // With a profile the value is an amplitude multiplier, 1 unless given.
      if (f.has("profile")) t.profile = read_profile(f, "profile");
      if (!f.has("profile") && !f.has("torque_Nm") && !f.has("force_N"))
        f.fail("torque_Nm", "give torque_Nm (revolute) or force_N (prismatic)");
      t.value = f.has("torque_Nm") ? f.num("torque_Nm") : f.num_or("force_N", 1.0);
      if (f.has("active_when")) t.active_when = read_rate_gate(f);
      s.joint_torques.push_back(t);
    } else if (type == "resistance") {
      Fields f(n, path, top.ctx(), {"type", "name", "body", "law", "coefficient", "dissipates"});
      Resistance r{name, f.str("body"), read_law(f, "law"), 0.0};
      if (f.has("coefficient") == f.has("dissipates"))
        f.fail("coefficient", "give either coefficient or dissipates: {power_W, cadence_Hz}");
      if (f.has("coefficient")) {
        r.coefficient = f.num("coefficient");
      } else {
        Fields d(f.raw("dissipates"), f.join("dissipates"), top.ctx(), {"power_W", "cadence_Hz"});
        const double power_W = d.num_in("power_W", 0.0, limits::kMaxPower_W, "W");
        const double cadence_Hz = d.num("cadence_Hz");
        if (!(cadence_Hz > 0.0 && cadence_Hz <= limits::kMaxCadence_Hz))
          d.fail("cadence_Hz", fmt::format("must be in (0, {:g}] Hz (got {:g})",
                                           limits::kMaxCadence_Hz, cadence_Hz));
        pending.push_back({s.resistances.size(), power_W, cadence_Hz, d.line()});
      }
      s.resistances.push_back(r);
    } else if (type == "spring") {
      Fields f(n, path, top.ctx(),
               {"type", "name", "body_a", "point_a", "body_b", "point_b", "stiffness_N_per_m",
                "rest_length_m"});
      Spring sp;
      sp.name = name;
      sp.body_a = f.str("body_a");
      sp.body_b = f.str("body_b");
      sp.point_a = read_point(f, "point_a", sp.body_a, s);
      sp.point_b = read_point(f, "point_b", sp.body_b, s);
      note_key(s, top.ctx(), "loads." + sp.name + ".point_b", f.raw("point_b"));  // checked at assembly
      sp.stiffness_N_per_m = f.num("stiffness_N_per_m");
      sp.rest_length_m = f.num("rest_length_m");
      s.springs.push_back(sp);
    } else if (type == "point_force") {
      // A muscle-like tension between two points; force_N is an amplitude with a profile.
      Fields f(n, path, top.ctx(),
               {"type", "name", "body_a", "point_a", "body_b", "point_b", "force_N", "active_when", "profile"});
      PointForce pf;
      pf.name = name;
      pf.body_a = f.str("body_a");
      pf.body_b = f.str("body_b");
      for (const auto& [key, body] : {std::pair{"body_a", pf.body_a}, std::pair{"body_b", pf.body_b}})
        if (body != kGround && !s.find_body(body)) f.fail(key, "unknown body '" + body + "'");
      pf.point_a = read_point(f, "point_a", pf.body_a, s);
      pf.point_b = read_point(f, "point_b", pf.body_b, s);
      note_key(s, top.ctx(), "loads." + pf.name + ".point_b", f.raw("point_b"));  // checked at assembly
      if (f.has("profile")) pf.profile = read_profile(f, "profile");
      if (!f.has("profile") && !f.has("force_N")) f.fail("force_N", "give force_N (the tension, positive pulls the points together)");
      pf.value = f.num_or("force_N", 1.0);
      if (f.has("active_when")) pf.active_when = read_rate_gate(f);
      s.point_forces.push_back(pf);
    } else if (type == "motor") {
      Fields f(n, path, top.ctx(),
               {"type", "name", "joint", "stall_torque_Nm", "stall_force_N", "no_load_speed_rad_s",
                "no_load_speed_m_s"});
      Motor m{name, f.str("joint"), 0.0, 0.0};
      using Keys = std::pair<std::string, std::string>;  // revolute's key, prismatic's key
      for (const auto& [torque_key, force_key] :
           {Keys{"stall_torque_Nm", "stall_force_N"}, Keys{"no_load_speed_rad_s", "no_load_speed_m_s"}}) {
        if (f.has(torque_key) && f.has(force_key))
          f.fail(torque_key, fmt::format("give {} (revolute) or {} (prismatic), not both", torque_key, force_key));
        check_unit_key(f, s, m.joint, torque_key, force_key);
      }
      m.stall_torque = f.has("stall_force_N") ? f.num("stall_force_N") : f.num("stall_torque_Nm");
      m.no_load_speed =
          f.has("no_load_speed_m_s") ? f.num("no_load_speed_m_s") : f.num("no_load_speed_rad_s");
      s.motors.push_back(m);
    } else {
      throw SceneError(
          top.file(), line_of(n["type"]), path + ".type",
          "unknown load type '" + type + "' (joint_torque, resistance, spring, motor, point_force)");
    }
  });
}

// initial: read before the mechanism, because the generator places the mechanism at q0.
void read_initial(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("initial")) return;
  Fields f(top.raw("initial"), "initial", ctx, {"q", "q_deg", "qdot", "cadence_Hz"});
  s.key_lines["initial"] = f.line();
  if (f.has("q") && f.has("q_deg")) f.fail("q", "give q or q_deg, not both");
  if (f.has("qdot") && f.has("cadence_Hz")) f.fail("qdot", "give qdot or cadence_Hz, not both");
  // Ranges in SI are check_scene's; the converted units are checked here, where the
  // message can quote them (the generator places the mechanism at q before that).
  s.initial.q = f.has("q_deg") ? f.num_abs_max("q_deg", 0.0, limits::kMaxAngle_rad * 180.0 / kPi,
                                               "degrees") *
                                     kPi / 180.0
                               : f.num_abs_max("q", 0.0, limits::kMaxAngle_rad, "rad or m");
  s.initial.qdot =
      f.has("cadence_Hz")
          ? f.num_abs_max("cadence_Hz", 0.0, limits::kMaxRate / (2.0 * kPi), "Hz") * 2.0 * kPi
          : f.num_or("qdot", 0.0);
}

// The mechanism: generated from bicycle_leg, or the scene's own bodies, joints, loops and gears.
void read_mechanism_or_leg(const Fields& top, const Context& ctx, Scene& s) {
  if (top.has("bicycle_leg")) {
    for (const char* k : {"bodies", "joints", "loops", "gears", "independent", "ground_points"})
      if (top.has(k))
        top.fail(k, "a bicycle_leg scene generates its own mechanism; remove this key");
    Fields f(top.raw("bicycle_leg"), "bicycle_leg", ctx,
             {"subject", "legs", "crank_length_m", "crank_mass_kg", "seat_tube_angle_deg",
              "knee_flexion_at_extension_deg", "ankle_angle_deg", "pedal_stack_m", "hip_torque_Nm",
              "flywheel", "resistance"});
    read_bicycle_leg(f, s);
  } else {
    read_mechanism(top, s);
  }
}

// A resistance given by `dissipates` (power at a cadence) becomes a coefficient once the
// mechanism and its gears are known: P = c·ωⁿ at the body's speed.
void resolve_dissipations(const Context& ctx, const std::vector<PendingDissipation>& pending,
                          Scene& s) {
  for (const auto& p : pending) {
    Resistance& r = s.resistances[p.index];
    if (!s.find_body(r.body))
      throw SceneError(ctx.file, p.line, "loads." + r.name + ".body",
                       "unknown body '" + r.body + "'");
    const auto ratio = fixed_speed_ratio(s, r.body);
    if (!ratio)
      throw SceneError(ctx.file, p.line, "loads." + r.name + ".dissipates",
                       "'dissipates' needs a body turning at a fixed ratio to the independent "
                       "coordinate (its child, or geared to it); give a coefficient instead");
    const double omega = std::abs(*ratio) * 2.0 * kPi * p.cadence_Hz;
    r.coefficient = p.power_W / std::pow(omega, dissipation_exponent(r.law));  // P = c·ωⁿ
  }
}

void read_gravity(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("gravity")) return;
  Fields f(top.raw("gravity"), "gravity", ctx, {"enabled", "g_m_s2"});
  s.gravity.enabled = f.flag_or("enabled", true);
  if (f.has("g_m_s2")) s.gravity.g_m_s2 = f.vec2("g_m_s2");
}

// Reads the YAML tree into `s` (names and shapes checked here, values by check_scene), section
// by section in the order the sections depend on each other: the first error found is reported.
void read_scene(const YAML::Node& root, const Context& ctx, Scene& s) {
  Fields top(
      root, "", ctx,
      {"name", "description", "bicycle_leg", "ground_points", "bodies", "joints", "loops", "gears",
       "independent", "independent_range", "independent_range_deg", "loads", "gravity", "outputs", "initial",
       "simulation", "validation", "optimize"});
  s.name = top.name("name");
  s.description = top.str_or("description", "");
  read_initial(top, ctx, s);
  read_mechanism_or_leg(top, ctx, s);
  read_independent_range(top, s);
  for (const char* k : {"independent_range", "independent_range_deg"})
    if (top.has(k)) note_key(s, ctx, k, top.raw(k));
  std::vector<PendingDissipation> pending;
  read_loads(top, s, pending);
  resolve_dissipations(ctx, pending, s);
  read_gravity(top, ctx, s);
  read_outputs(top, ctx, s);
  read_simulation(top, ctx, s);
  read_validation(top, ctx, s);
  if (top.has("optimize")) read_optimize(Fields(top.raw("optimize"), "optimize", ctx,
                                                {"loads", "of", "force", "harmonics", "max_load", "nonnegative",
                                                 "objective", "p"}),
                                         s);
}

}  // namespace

Override parse_override(const std::string& text) {
  const auto eq = text.find('=');
  const std::string shown = text.substr(0, 80) + (text.size() > 80 ? "…" : "");
  if (eq == std::string::npos)
    throw SceneError("", 0, "--set " + shown, "expected key.path=value (no '=')");
  if (eq == 0) throw SceneError("", 0, "--set " + shown, "expected key.path=value (empty key)");
  Override o{text.substr(0, eq), text.substr(eq + 1)};
  if (o.path.size() > kMaxOverrideKeyLength)
    throw SceneError("", 0, "--set " + shown,
                     fmt::format("key path longer than {} characters", kMaxOverrideKeyLength));
  if (o.value.size() > limits::kMaxTextLength)
    throw SceneError("", 0, "--set " + shown,
                     fmt::format("value longer than {} characters", limits::kMaxTextLength));
  const auto parts = split_key_path(o.path);
  if (std::any_of(parts.begin(), parts.end(), [](const std::string& p) { return p.empty(); }))
    throw SceneError("", 0, "--set " + shown, "malformed key path (an empty part between dots)");
  return o;
}

namespace {
// The shipped scenes of an installed rdyn: <exe dir>/RDYN_INSTALLED_SCENES_REL (CMake computes
// it from the install layout, ../share/rdyn/scenes), so an install prefix can be moved.
// Empty when the executable's path is unknown. A build-tree executable has no such folder.
std::string installed_scenes_dir() {
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0) return "";
  const std::string path(exe, static_cast<size_t>(n));
  const auto slash = path.rfind('/');
  if (slash == std::string::npos) return "";
  return path.substr(0, slash + 1) + RDYN_INSTALLED_SCENES_REL;
}
}  // namespace

std::string resolve_scene_path(const std::string& name_or_path) {
  struct stat st {};
  if (stat(name_or_path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw SceneError(name_or_path, 0, "", "is a folder, not a scene file");
    return name_or_path;
  }
  const bool plain_name = name_or_path.find('/') == std::string::npos &&
                          name_or_path.find('.') == std::string::npos && !name_or_path.empty();
  if (plain_name) {
    std::vector<std::string> dirs;
    if (const char* env = std::getenv("RDYN_SCENES_DIR")) dirs.push_back(env);
    if (std::string installed = installed_scenes_dir(); !installed.empty()) dirs.push_back(installed);
    dirs.push_back(RDYN_SCENES_DIR);  // the source folder (build tree)
    for (const auto& d : dirs) {
      const std::string p = d + "/" + name_or_path + ".yaml";
      if (stat(p.c_str(), &st) == 0) return p;
    }
  }
  throw SceneError(name_or_path, 0, "", "no such scene file (nor a shipped scene of that name)");
}

Scene parse_scene(const std::string& text, const std::string& file, const std::vector<Override>& overrides) {
  return read_scene_tree(load_checked_yaml(text, file), file, overrides);
}

Scene yaml::read_scene_tree(YAML::Node root, const std::string& file, const std::vector<Override>& overrides) {
  Context ctx{file, {}};
  for (const auto& o : overrides) apply_override(root, o, file, &ctx.set_by_override);
  // The overrides may have added nodes: check the tree they left (duplicates cannot arise,
  // but depth and size can grow with created mappings).
  if (!overrides.empty()) check_yaml_tree(root, file);
  Scene s;
  s.source_file = file;
  try {
    read_scene(root, ctx, s);
    check_scene(s);
  } catch (const YAML::Exception& e) {
    throw SceneError(file, e.mark.is_null() ? 0 : e.mark.line + 1, "", e.msg);
  } catch (const SceneError& e) {
    // check_scene and the generator know the field, not the line: find it in the tree.
    if (e.line() > 0 || e.field().empty() || e.field().rfind("--set", 0) == 0) throw;
    const YAML::Node n = locate_field(root, e.field());
    ctx.fail(n, e.field(), e.message());
  }
  return s;
}

std::string normalise_text_encoding(std::string text) {
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  if (text.find('\n') == std::string::npos) std::replace(text.begin(), text.end(), '\r', '\n');
  return text;
}

std::string non_regular_file_kind(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || S_ISREG(st.st_mode)) return "";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISDIR(st.st_mode)) return "a folder";
  if (S_ISCHR(st.st_mode)) return "a character device";
  if (S_ISBLK(st.st_mode)) return "a block device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "not a file";
}

std::string read_scene_text(const std::string& name_or_path) {
  const std::string path = resolve_scene_path(name_or_path);
  if (const std::string kind = non_regular_file_kind(path); !kind.empty())
    throw SceneError(path, 0, "", "not a regular file (" + kind + "): give a scene file (a FIFO would block, a "
                                  "device never ends)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, 0, "", "cannot open for reading");
  // Read at most one byte more than a scene may have: /dev/zero or a huge file cannot
  // exhaust memory (parse_scene refuses the oversized text with its size limit). In chunks: a
  // 1 MB buffer zeroed for a scene of a few kB was ~10 % of a sweep case's scene stage.
  std::string text;
  char chunk[1 << 14];
  while (text.size() <= kMaxSceneBytes) {
    const size_t want = std::min(sizeof chunk, kMaxSceneBytes + 1 - text.size());
    in.read(chunk, static_cast<std::streamsize>(want));
    const auto got = static_cast<size_t>(std::max<std::streamsize>(0, in.gcount()));
    text.append(chunk, got);
    if (got < want) break;
  }
  return text;
}

Scene load_scene(const std::string& name_or_path, const std::vector<Override>& overrides) {
  return parse_scene(read_scene_text(name_or_path), resolve_scene_path(name_or_path), overrides);
}

namespace {
// Node at a dotted path (map keys; list items by index or name), or an invalid node.
bool find_path(YAML::Node root, const std::string& path, YAML::Node& parent, std::string& last) {
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  if (parts.empty()) return false;
  YAML::Node cur;
  cur.reset(root);
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next;
    bool found = false;
    if (cur.IsMap() && cur[parts[i]]) {
      next.reset(cur[parts[i]]);
      found = true;
    } else if (cur.IsSequence()) {
      for (size_t k = 0; k < cur.size() && !found; ++k)
        if (cur[k].IsMap() && cur[k]["name"] && cur[k]["name"].Scalar() == parts[i])
          next.reset(cur[k]), found = true;
    }
    if (!found) return false;
    cur.reset(next);
  }
  parent.reset(cur);
  last = parts.back();
  return cur.IsMap() && static_cast<bool>(cur[last]);
}
}  // namespace

bool scene_yaml_has(const std::string& text, const std::string& path) {
  try {
    YAML::Node root = load_checked_yaml(text, ""), parent;
    std::string last;
    return find_path(root, path, parent, last);
  } catch (const YAML::Exception&) {
    return false;
  } catch (const SceneError&) {
    return false;
  }
}

std::string rewrite_scene_yaml(const std::string& text, const std::string& file,
                               const std::vector<Override>& overrides,
                               const std::vector<std::string>& remove) {
  YAML::Node root = load_checked_yaml(text, file);
  for (const auto& path : remove) {
    YAML::Node parent;
    std::string last;
    if (find_path(root, path, parent, last)) parent.remove(last);
  }
  for (const auto& o : overrides) apply_override(root, o, file);
  YAML::Emitter out;
  out << root;
  return std::string(out.c_str()) + "\n";
}

}  // namespace rdyn::models
