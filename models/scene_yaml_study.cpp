// The study sections of a scene (what to output, how to simulate, validate and optimize it), read
// by models/scene_yaml.cpp's read_scene with the checked fields of models/yaml_fields.hpp.
#include "models/scene_yaml_study.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>

namespace rdyn::models::yaml {

// The `optimize` block (rdyn optimize): every name known, every number in range, here where
// the line is known.
void read_optimize(const Fields& f, Scene& s) {
  OptimizeSpec o;
  std::vector<YAML::Node> same_nodes;
  for_each_item(f, "loads", [&](const YAML::Node& n, const std::string& path) {
    Fields l(n, path, f.ctx(), {"load", "same_as", "shift_deg", "shift_rad"});
    OptimizeLoad d;
    d.load = l.name("load");
    // That the load exists is checked when optimizing (validate/analysis/optimize.cpp, resolve_design),
    // at this line: a scene whose drive is switched off (a generator's hip_torque_Nm: 0, "no
    // drive") makes no such torque, and simulate, extract or inspect of it must not be refused
    // for a block only `rdyn optimize` reads (issue #23).
    note_key(s, f.ctx(), fmt::format("optimize.loads[{}].load", o.loads.size()), n["load"]);
    for (const auto& e : o.loads)
      if (e.load == d.load) l.fail("load", "'" + d.load + "' is listed twice");
    if (l.has("same_as")) {
      d.same_as = l.name("same_as");
      if (d.same_as == d.load) l.fail("same_as", "a load cannot take its own shape");
    }
    for (const char* k : {"shift_deg", "shift_rad"})
      if (l.has(k) && !l.has("same_as")) l.fail(k, "a shift needs same_as");
    if (l.has("shift_deg") && l.has("shift_rad")) l.fail("shift_rad", "give shift_deg or shift_rad, not both");
    // shift_rad: how rdyn writes it back (degrees do not reach every radian value exactly).
    d.shift_rad = l.has("shift_rad") ? l.num_abs_max("shift_rad", 0.0, 2 * kPi, "rad")
                                     : l.num_abs_max("shift_deg", 0.0, 360.0, "degrees") * kPi / 180.0;
    o.loads.push_back(d);
    same_nodes.push_back(n);
  });
  if (f.has("loads") && o.loads.empty()) f.fail("loads", "list at least one design load, or leave the key out");
  // Where the design is written: the refusals that need the whole design (calibration scales
  // every joint torque together) come after loading.
  s.key_lines["optimize"] = f.line();
  if (f.has("loads")) note_key(s, f.ctx(), "optimize.loads", f.raw("loads"));
  for (size_t i = 0; i < o.loads.size(); ++i) {
    const auto& d = o.loads[i];
    if (d.same_as.empty()) continue;
    const auto it = std::find_if(o.loads.begin(), o.loads.end(), [&](const OptimizeLoad& e) { return e.load == d.same_as; });
    const std::string path = f.join("loads") + fmt::format("[{}].same_as", i);
    if (it == o.loads.end())
      f.fail_at(same_nodes[i]["same_as"], path, "'" + d.same_as + "' is not a design load listed in optimize.loads");
    if (!it->same_as.empty())
      f.fail_at(same_nodes[i]["same_as"], path,
                "'" + d.same_as + "' takes its shape from '" + it->same_as + "': name that load instead");
  }
  if (f.has("of")) {
    o.of = f.name("of");
    const Joint* j = s.find_joint(o.of);
    if (!j) f.fail("of", "unknown joint '" + o.of + "'");
    if (j->type != JointType::Revolute) f.fail("of", "a profile reads a revolute joint's angle");
  }
  if (f.has("force")) {
    o.force = f.name("force");
    const auto& cf = s.outputs.constraint_forces;
    if (std::none_of(cf.begin(), cf.end(), [&](const ConstraintForceRequest& c) { return c.name == o.force; }))
      f.fail("force", "no requested constraint force named '" + o.force + "' (outputs.constraint_forces)");
  }
  if (f.has("harmonics")) {
    const double h = f.num_in("harmonics", 1, kMaxOptimizeHarmonics, "");
    if (h != std::floor(h)) f.fail("harmonics", fmt::format("must be a whole number (got {:g})", h));
    o.harmonics = static_cast<int>(h);
  }
  if (f.has("max_load")) {
    o.max_load = f.num("max_load");
    if (!(o.max_load > 0 && o.max_load <= limits::kMaxForce))
      f.fail("max_load", fmt::format("must be in (0, {:g}] N·m or N (got {:g})", limits::kMaxForce, o.max_load));
  }
  o.nonnegative = f.flag_or("nonnegative", true);
  o.objective = f.str_or("objective", "peak");
  if (o.objective != "peak" && o.objective != "pnorm") f.fail("objective", "expected peak or pnorm");
  if (f.has("p")) {
    o.p = f.num_in("p", 2, 64, "");
    if (o.objective != "pnorm") f.fail("p", "an exponent needs objective: pnorm");
  }
  s.optimize = o;
}

namespace {

// outputs.constraint_forces: name, joint and a direction (a vector, or a named point of the
// joint's child), stored as a unit vector.
void read_constraint_force_requests(const Fields& f, const Context& ctx, Scene& s) {
  for_each_item(f, "constraint_forces", [&](const YAML::Node& n, const std::string& path) {
    Fields c(n, path, ctx, {"name", "joint", "direction"});
    ConstraintForceRequest r{c.name("name"), c.str("joint"), {}};
    const Joint* j = s.find_joint(r.joint);
    if (!j) c.fail("joint", "unknown joint '" + r.joint + "'");
    const YAML::Node d = c.required("direction");
    if (d.IsScalar()) {  // toward a named point of the child, from the joint
      const Vec2 to = read_point(c, "direction", j->child, s);
      r.direction = {to.x - j->child_point.x, to.y - j->child_point.y};
    } else {
      r.direction = c.vec2("direction");
    }
    const double len = std::hypot(r.direction.x, r.direction.y);
    if (len < 1e-12) c.fail("direction", "must be a non-zero vector");
    r.direction = unit_vector(r.direction, len);
    for (const auto& other : s.outputs.constraint_forces)
      if (other.name == r.name) c.fail("name", "duplicate constraint force name");
    s.outputs.constraint_forces.push_back(r);
  });
}

void read_output_bodies(const Fields& f, Scene& s) {
  if (!f.has("bodies")) return;
  const YAML::Node b = f.raw("bodies");
  if (!b.IsSequence()) f.fail("bodies", "expected a list of body names");
  for (size_t i = 0; i < b.size(); ++i) {
    // A body name, not a mapping or a list (yaml-cpp would only say "bad conversion").
    if (!b[i].IsScalar()) f.fail_at(b[i], fmt::format("outputs.bodies[{}]", i), "expected a body name");
    s.outputs.bodies.push_back(b[i].as<std::string>());
  }
}

// `all` or a list of names; each name known (joints; for reactions, joints or loops).
std::vector<std::string> read_names_or_all(const Fields& f, const Scene& s, const std::string& key,
                                           bool loops_too) {
  std::vector<std::string> out;
  const YAML::Node n = f.raw(key);
  const std::string what = loops_too ? "joint or loop" : "joint";
  if (n.IsScalar() && n.Scalar() == "all") {
    for (const auto& j : s.joints) out.push_back(j.name);
    if (loops_too)
      for (const auto& l : s.loops) out.push_back(l.name);
  } else if (n.IsSequence()) {
    for (const auto& item : n) {
      const std::string name = item.IsScalar() ? item.Scalar() : "";
      const bool loop = loops_too && std::any_of(s.loops.begin(), s.loops.end(),
                                                 [&](const Loop& l) { return l.name == name; });
      if (!s.find_joint(name) && !loop)
        f.fail_at(item, f.join(key), "unknown " + what + " '" + name.substr(0, 64) + "'");
      if (std::find(out.begin(), out.end(), name) != out.end())
        f.fail_at(item, f.join(key), "'" + name + "' is listed twice");
      out.push_back(name);
    }
  } else {
    f.fail(key, "expected all or a list of " + what + " names");
  }
  for (const auto& name : out)  // R_<name> must say which one it is
    if (loops_too && s.find_joint(name) &&
        std::any_of(s.loops.begin(), s.loops.end(), [&](const Loop& l) { return l.name == name; }))
      f.fail(key, "'" + name + "' names both a joint and a loop: rename one");
  return out;
}

}  // namespace

void read_outputs(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("outputs")) return;
  Fields f(top.raw("outputs"), "outputs", ctx, {"constraint_forces", "bodies", "joints", "reactions", "shaking"});
  read_constraint_force_requests(f, ctx, s);
  read_output_bodies(f, s);
  if (f.has("joints")) s.outputs.joints = read_names_or_all(f, s, "joints", false);
  if (f.has("reactions")) {
    s.outputs.reactions = read_names_or_all(f, s, "reactions", true);
    const YAML::Node r = f.raw("reactions");
    s.outputs.reactions_all = r.IsScalar() && r.Scalar() == "all";
    note_key(s, f.ctx(), "outputs.reactions", f.raw("reactions"));
  }
  s.outputs.shaking = f.flag_or("shaking", false);
}

void read_simulation(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("simulation")) return;
  Fields f(top.raw("simulation"), "simulation", ctx,
           {"duration_s", "output_interval_s", "tolerance"});
  s.simulation.duration_s = f.num_or("duration_s", s.simulation.duration_s);
  s.simulation.output_interval_s = f.num_or("output_interval_s", s.simulation.output_interval_s);
  s.simulation.tolerance = f.num_or("tolerance", s.simulation.tolerance);
}

namespace {

// validation.calibrate: the operating point (cadence, and power or mean-speed mode) and the load
// calibrated to reach it.
void read_calibrate(const Fields& f, const Context& ctx, Scene& s) {
  if (!f.has("calibrate")) return;
  Fields c(f.raw("calibrate"), "validation.calibrate", ctx, {"cadence_Hz", "power_W", "load", "grid_deg"});
  s.validation.calibrate_cadence_Hz = c.num("cadence_Hz");
  // power_W absent: mean-speed mode (the resistances stay as given).
  s.validation.calibrate_power_W = c.num_or("power_W", 0.0);
  s.validation.calibrate_load = c.str_or("load", "");  // checked against the loads by calibrate
  s.validation.calibrate_grid_deg = c.num_or("grid_deg", 10.0);  // range: check_scene
  s.validation.calibrate_grid_given = c.has("grid_deg");
  if (c.has("load")) note_key(s, ctx, "validation.calibrate.load", c.raw("load"));
  if (c.has("load") && s.validation.calibrate_load.empty())
    c.fail("load", "an empty name names no load: give a joint_torque or motor, or leave the key out");
  // A present block with zeros would silently mean "off": refuse (ranges: check_scene).
  if (!(s.validation.calibrate_cadence_Hz > 0)) c.fail("cadence_Hz", "must be positive");
  if (c.has("power_W") && !(s.validation.calibrate_power_W > 0)) c.fail("power_W", "must be positive");
}

// Published values the report sets beside the calibration's (e.g. the original authors'
// hip torque): plain text, HTML-escaped by the report.
void read_compare(const Fields& f, const Context& ctx, Scene& s) {
  for_each_item(f, "compare", [&](const YAML::Node& n, const std::string& path) {
    Fields c(n, path, ctx, {"quantity", "value", "unit", "source", "explanation"});
    CompareValue cv{c.str("quantity"), c.num("value"), c.str_or("unit", ""), c.str_or("source", ""),
                    c.str_or("explanation", "")};
    if (std::find(kCompareQuantities.begin(), kCompareQuantities.end(), cv.quantity) ==
        kCompareQuantities.end())
      c.fail("quantity", "expected drive_torque_Nm, peak_force_N, speed_fluctuation or mean_power_W");
    if (!std::isfinite(cv.value)) c.fail("value", "must be a finite number");
    if (!f.has("calibrate"))
      c.fail("quantity", "compared values are calibration results: add validation.calibrate");
    s.validation.compare.push_back(cv);
  });
}

}  // namespace

void read_validation(const Fields& top, const Context& ctx, Scene& s) {
  if (!top.has("validation")) return;
  Fields f(top.raw("validation"), "validation", ctx,
           {"duration_s", "thresholds", "calibrate", "note", "reference_tolerance",
            "reference_integrator", "compare"});
  s.validation.duration_s = f.num_or("duration_s", 0.0);
  s.validation.reference_tolerance = f.num_or("reference_tolerance", 1e-10);
  s.validation.reference_integrator = f.str_or("reference_integrator", "rkmerson");
  const auto& ri = s.validation.reference_integrator;
  if (ri != "rkmerson" && ri != "rk3" && ri != "cpodes")
    f.fail("reference_integrator", "expected rkmerson, rk3 or cpodes");
  s.validation.note = f.str_or("note", "");
  for_each_item(f, "thresholds", [&](const YAML::Node& n, const std::string& path) {
    Fields t(n, path, ctx, {"quantity", "grid_deg", "interpolation", "max_error"});
    Threshold th{t.str("quantity"), t.num_or("grid_deg", 10.0), t.str_or("interpolation", ""),
                 t.num("max_error")};
    // quantity, grid_deg, max_error: check_scene.
    s.validation.thresholds.push_back(th);
  });
  read_calibrate(f, ctx, s);
  read_compare(f, ctx, s);
}

}  // namespace rdyn::models::yaml
