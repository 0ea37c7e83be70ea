#include "validate/analysis/calibration_load.hpp"

#include <cmath>
#include <optional>

#include <fmt/format.h>

namespace rdyn::validate {

namespace {

// The index of the first element of `v` (loads of one kind) named `name`; none: empty.
template <class Load>
std::optional<size_t> index_named(const std::vector<Load>& v, const std::string& name) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].name == name) return i;
  return std::nullopt;
}

}  // namespace

// The value of entry e in the scene / in the reduced model (its torques, motors and point
// forces are the scene's, in order).
double& value_of(models::Scene& s, const Entry& e) {
  return e.motor ? s.motors[e.index].stall_torque
                 : e.point_force ? s.point_forces[e.index].value : s.joint_torques[e.index].value;
}
double& value_of(reduced::ReducedModel& m, const Entry& e) {
  return e.motor ? m.motors[e.index].stall : e.point_force ? m.point_forces[e.index].value : m.torques[e.index].value;
}
const std::string& name_of(const models::Scene& s, const Entry& e) {
  return e.motor ? s.motors[e.index].name : e.point_force ? s.point_forces[e.index].name : s.joint_torques[e.index].name;
}

const char* unit_of(const models::Scene& s, const std::string& joint) {
  const auto* j = s.find_joint(joint);
  return j && j->type == models::JointType::Prismatic ? "N" : "N·m";
}

Selection select_load(const models::Scene& scene, const CalibrationOptions& opt) {
  auto fail = [&](const std::string& field, const std::string& msg) {
    throw models::SceneError(scene.source_file, scene.line_of(field), scene.field_of(field), msg);
  };
  auto candidates = [&] {
    std::string c;
    for (const auto& t : scene.joint_torques) c += (c.empty() ? "" : ", ") + t.name;
    for (const auto& m : scene.motors) c += (c.empty() ? "" : ", ") + m.name;
    for (const auto& f : scene.point_forces) c += (c.empty() ? "" : ", ") + f.name;
    return c.empty() ? std::string("the scene has none") : "the scene has " + c;
  };
  Selection sel;
  if (opt.load.empty()) {
    if (scene.joint_torques.empty())
      fail("validation.calibrate.load",
           "name the load to calibrate (validation.calibrate.load or --load): without a name every joint "
           "torque is scaled together, and the scene has no joint torque (" + candidates() + ")");
    std::string units;
    for (size_t i = 0; i < scene.joint_torques.size(); ++i) {
      const auto& t = scene.joint_torques[i];
      sel.entries.push_back({false, i, t.value < 0 ? -1.0 : 1.0});
      sel.name += (sel.name.empty() ? "" : "+") + t.name;
      const std::string u = unit_of(scene, t.joint);
      if (units.empty()) units = u;
      // One magnitude in two units is no load at all: a Whitworth's 20 N·m crank torque and
      // −50 N ram force both came out 1.7 (and the scene written with −1.7 N), as `--load a+b`
      // already refuses.
      if (units != u)
        fail("validation.calibrate.load",
             fmt::format("name the load to calibrate (validation.calibrate.load or --load): without a name every "
                         "joint torque is scaled to one magnitude, and joint torque '{}' is in {} while '{}' is in {}",
                         scene.joint_torques[0].name, units, t.name, u));
    }
    sel.kind = "joint_torques";
    sel.unit = units;
    return sel;
  }
  if (opt.load.find('+') != std::string::npos) {
    // Several loads scaled together (a muscle on each leg): each is selected by its own name,
    // all in one unit; each gets sign·T, the result is the magnitude T.
    std::string rest = opt.load + "+";
    std::string kinds;
    for (size_t at; (at = rest.find('+')) != std::string::npos; rest.erase(0, at + 1)) {
      CalibrationOptions one = opt;
      one.load = rest.substr(0, at);
      if (one.load.empty())
        fail(opt.load_field, "'" + opt.load + "' has an empty name: give names joined by '+' (a+b)");
      const Selection part = select_load(scene, one);
      if (part.entries[0].motor)
        fail(opt.load_field, "motor '" + one.load + "' is calibrated alone (its power depends on the speed): name "
                             "joint torques or point forces with '+'");
      for (const auto& e : sel.entries)
        if (e.index == part.entries[0].index && e.motor == part.entries[0].motor &&
            e.point_force == part.entries[0].point_force)
          fail(opt.load_field, "'" + one.load + "' is named twice in '" + opt.load + "'");
      if (!sel.unit.empty() && sel.unit != part.unit)
        fail(opt.load_field, fmt::format("'{}' mixes units ({} and {}): loads calibrated together share one unit",
                                         opt.load, sel.unit, part.unit));
      sel.unit = part.unit;
      sel.entries.push_back(part.entries[0]);
      kinds = kinds.empty() || kinds == part.kind ? part.kind : "loads";
    }
    sel.name = opt.load;
    sel.kind = kinds == "loads" ? kinds : kinds + "s";  // point_forces, joint_torques, ...
    sel.together = true;
    return sel;
  }
  if (!models::is_valid_name(opt.load)) fail(opt.load_field, models::invalid_name_message(opt.load));
  sel.name = opt.load;
  auto selected = [&](Entry e, const std::string& unit, const std::string& kind) {
    sel.entries.push_back(e);
    sel.unit = unit;
    sel.kind = kind;
    return sel;
  };
  if (const auto i = index_named(scene.joint_torques, opt.load)) {
    const auto& t = scene.joint_torques[*i];
    const std::string unit = unit_of(scene, t.joint);
    return selected({false, *i, t.value < 0 ? -1.0 : 1.0}, unit, unit == "N" ? "joint_force" : "joint_torque");
  }
  if (const auto i = index_named(scene.motors, opt.load)) {
    // The stall torque keeps the no-load speed's sign (check_scene: same signs).
    const auto& m = scene.motors[*i];
    const std::string unit = unit_of(scene, m.joint);
    return selected({true, *i, m.no_load_speed < 0 ? -1.0 : 1.0}, unit,
                    unit == "N" ? "motor_stall_force" : "motor_stall_torque");
  }
  // A point force's tension [N] (the amplitude with a profile): work per revolution per newton, like a torque.
  if (const auto i = index_named(scene.point_forces, opt.load))
    return selected({false, *i, scene.point_forces[*i].value < 0 ? -1.0 : 1.0, true}, "N", "point_force");
  if (index_named(scene.resistances, opt.load))
    fail(opt.load_field, "'" + opt.load + "' is a resistance: calibrate adjusts a drive load, a joint_torque, "
                         "point_force or motor (" + candidates() + "); the resistance follows from --power-w");
  if (index_named(scene.springs, opt.load))
    fail(opt.load_field, "'" + opt.load + "' is a spring, which does no net work per revolution: calibrate adjusts "
                         "a joint_torque or a motor (" + candidates() + ")");
  fail(opt.load_field, "no joint_torque, point_force or motor named '" + opt.load + "' (" + candidates() + ")");
  return sel;
}

models::Scene with_load(models::Scene s, const Selection& sel, double T, double coefficient) {
  for (const auto& e : sel.entries) value_of(s, e) = e.sign * T;
  if (std::isfinite(coefficient)) s.resistances[0].coefficient = coefficient;
  return s;
}

models::Scene scene_at_operating_point(const models::Scene& scene, const CalibrationOptions& opt,
                                       const CalibrationResult& r) {
  models::Scene s = with_load(scene, select_load(scene, opt), std::abs(r.load_value), r.resistance_coefficient);
  s.initial = models::Initial{r.steady_q, r.steady_qdot};
  return s;
}

void set_load(reduced::ReducedModel& m, const Selection& sel, double T) {
  for (const auto& e : sel.entries) value_of(m, e) = e.sign * T;
}

}  // namespace rdyn::validate
