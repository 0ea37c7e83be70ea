#include "validate/analysis/calibrated_scene.hpp"

#include <cmath>

#include <fmt/format.h>

#include "models/scene_yaml.hpp"
#include "validate/analysis/calibration_load.hpp"

namespace rdyn::validate {

namespace {

// The YAML key holding the value of load entry `e` (empty: not a key of the text, i.e. made
// by the bicycle_leg generator).
std::string value_key(const std::string& text, const models::Scene& scene, const Entry& e) {
  const std::string base = "loads." + name_of(scene, e) + ".";
  // A point force listed in the text: force_N (created when a profiled one leaves it at 1).
  if (e.point_force) return models::scene_yaml_has(text, base + "type") ? base + "force_N" : "";
  for (const char* k : e.motor ? std::vector<const char*>{"stall_torque_Nm", "stall_force_N"}
                               : std::vector<const char*>{"torque_Nm", "force_N"})
    if (models::scene_yaml_has(text, base + k)) return base + k;
  return "";
}

}  // namespace

void check_writable(const std::string& text, const models::Scene& scene, const CalibrationOptions& opt) {
  const Selection sel = select_load(scene, opt);
  if (opt.load.empty() && models::scene_yaml_has(text, "bicycle_leg")) return;  // hip_torque_Nm
  for (const auto& e : sel.entries)
    if (value_key(text, scene, e).empty())
      throw models::SceneError(scene.source_file, 0, "--write-scene",
                               "'" + sel.name + "' is made by the scene's generator, not written in its loads: "
                               "only the generator's own drive value (every joint torque, no --load) can be written");
}

std::string calibrated_scene_yaml(const std::string& source, const std::string& text,
                                  const std::vector<models::Override>& base, const models::Scene& scene,
                                  const CalibrationOptions& opt, const CalibrationResult& r) {
  check_writable(text, scene, opt);
  const Selection sel = select_load(scene, opt);
  const double T = std::abs(r.load_value);
  std::vector<models::Override> o = base;
  auto num = [](double v) { return fmt::format("{:.12g}", v); };
  const bool generated_drive = opt.load.empty() && models::scene_yaml_has(text, "bicycle_leg");
  if (generated_drive) {
    // Torques the scene lists under `loads` (profiled hips, say) are scaled there; the
    // generated constant hip torques through hip_torque_Nm, only when the generator made some.
    bool generated = false;
    for (const auto& t : scene.joint_torques) {
      if (!models::scene_yaml_has(text, "loads." + t.name + ".joint")) {
        generated = true;
        continue;
      }
      // The joint's unit decides the key (scene_yaml refuses the other one).
      const models::Joint* j = scene.find_joint(t.joint);
      const std::string key = j && j->type == models::JointType::Prismatic ? "force_N" : "torque_Nm";
      o.push_back({"loads." + t.name + "." + key, num((t.value < 0 ? -1 : 1) * T)});
    }
    if (generated) o.push_back({"bicycle_leg.hip_torque_Nm", num(T)});
  } else {
    for (const auto& e : sel.entries) o.push_back({value_key(text, scene, e), num(e.sign * T)});
  }
  // power_W at cadence_Hz means c = power_W/ω_Fⁿ (constant speed): the nominal power that gives
  // the calibrated coefficient, which dissipates P on the fluctuating steady cycle.
  const std::string nominal_w =
      opt.power_w > 0 ? fmt::format("{:.17g}", opt.power_w * r.resistance_coefficient /
                                                   calc_resistance_coefficient(scene, opt))
                      : std::string();
  bool nominal = false;  // the power went in as a nominal power_W (else as the coefficient itself)
  if (opt.power_w > 0) {
    if (models::scene_yaml_has(text, "bicycle_leg")) {
      nominal = true;
      o.push_back({"bicycle_leg.resistance.power_W", nominal_w});
      o.push_back({"bicycle_leg.resistance.cadence_Hz", num(opt.cadence_hz)});
    } else {
      const auto& res = scene.resistances[0];
      if (models::scene_yaml_has(text, "loads." + res.name + ".dissipates")) {
        nominal = true;
        o.push_back({"loads." + res.name + ".dissipates.power_W", nominal_w});
        o.push_back({"loads." + res.name + ".dissipates.cadence_Hz", num(opt.cadence_hz)});
      } else {
        o.push_back({"loads." + res.name + ".coefficient", num(r.resistance_coefficient)});
      }
    }
  }
  o.push_back({"initial.q", fmt::format("{:.17g}", r.steady_q)});
  o.push_back({"initial.qdot", fmt::format("{:.17g}", r.steady_qdot)});
  const std::string body = models::rewrite_scene_yaml(
      text, scene.source_file, o, {"initial.q", "initial.q_deg", "initial.qdot", "initial.cadence_Hz"});
  // The source name goes into a YAML comment: one line, no control characters (a file name
  // with a newline must not add keys to the scene).
  std::string from;
  for (char c : source) from += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  // The nominal-power remark only where the scene holds a power_W: a scene that gives the
  // coefficient gets the coefficient, and a remark about a power_W it has not would mislead.
  std::string point = "with the resistances as given";
  if (opt.power_w > 0)
    point = nominal ? fmt::format("with the resistance dissipating {:.6g} W on the steady cycle at {:.6g} Hz (its\n"
                                  "# power_W is nominal: the power of its coefficient at a constant {:.6g} Hz)",
                                  opt.power_w, opt.cadence_hz, opt.cadence_hz)
                    : fmt::format("with the resistance dissipating {:.6g} W on the steady cycle at {:.6g} Hz (its\n"
                                  "# coefficient set to {:.6g})",
                                  opt.power_w, opt.cadence_hz, r.resistance_coefficient);
  // An unconfirmed result (written with --force) says so in its first comment, on one line each.
  std::string warning;
  if (!r.unconfirmed.empty()) {
    warning = "# NOT CONFIRMED on the full model (written with --force): ";
    for (char c : r.unconfirmed) warning += c == '\n' ? ' ' : c;
    warning += "\n";
  }
  return fmt::format(
      "# Calibrated by `rdyn calibrate` from {}: {} ({}) = {:.6g} {} holds a mean cadence of {:.6g} Hz\n"
      "# (reduced) / {} (full) {}. The initial\n"
      "# conditions are a point of the steady cycle.\n{}{}",
      from, r.load, r.load_kind, r.load_value, r.load_unit, r.mean_cadence_hz_reduced,
      std::isfinite(r.mean_cadence_hz_full) ? fmt::format("{:.6g} Hz", r.mean_cadence_hz_full) : "no measure",
      point, warning, body);
}

}  // namespace rdyn::validate
