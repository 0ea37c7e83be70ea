#include "models/scene_write.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "models/scene_hash.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::models {

namespace {

constexpr double kPi = 3.14159265358979323846;

// One UTF-8 sequence at s[i]: its code point and length, or length 0 when the bytes are not
// well-formed UTF-8 (overlong forms, surrogates and code points above U+10FFFF included; Unicode
// 15, Table 3-7).
struct CodePoint {
  char32_t value = 0;
  size_t length = 0;
};
CodePoint decode_utf8(const std::string& s, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b0 = byte(i);
  if (b0 < 0x80) return {b0, 1};
  size_t n = 0;
  char32_t cp = 0, min = 0;
  if ((b0 & 0xE0) == 0xC0)
    n = 2, cp = b0 & 0x1F, min = 0x80;
  else if ((b0 & 0xF0) == 0xE0)
    n = 3, cp = b0 & 0x0F, min = 0x800;
  else if ((b0 & 0xF8) == 0xF0)
    n = 4, cp = b0 & 0x07, min = 0x10000;
  else
    return {};
  if (i + n > s.size()) return {};
  for (size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return {};
    cp = (cp << 6) | (byte(i + k) & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return {};
  return {cp, n};
}

// Writes the YAML text; every value goes through one of these so that each reads back equal.
class Writer {
 public:
  explicit Writer(const Scene& s) : file_(s.source_file) {}

  // The shortest text that reads back to the same double (fmt's "{}", Ryu-like shortest round
  // trip); the reader refuses non-finite and subnormal values, so the writer does too.
  std::string num(double v, const std::string& field) const {
    if (!std::isfinite(v))
      throw SceneError(file_, 0, field, "is not finite: a scene file cannot hold it");
    if (v != 0.0 && std::abs(v) < std::numeric_limits<double>::min())
      throw SceneError(file_, 0, field,
                       fmt::format("{} is subnormal (below 2.2e-308 in "
                                   "magnitude): the scene reader refuses it",
                                   v));
    return fmt::format("{}", v);
  }
  std::string vec(const Vec2& v, const std::string& field) const {
    return "[" + num(v.x, field + "[0]") + ", " + num(v.y, field + "[1]") + "]";
  }
  // Text: plain when it is a name YAML reads back as the same string (not null, a boolean or
  // empty), double-quoted otherwise, with every character YAML would fold, drop or misread escaped
  // (YAML 1.2, §5.7 escape sequences; §5.4 line breaks incl. NEL, LS, PS).
  std::string text(const std::string& s) const {
    if (is_plain_safe(s)) return s;
    std::string out = "\"";
    for (size_t i = 0; i < s.size();) {
      const CodePoint c = decode_utf8(s, i);
      if (c.length == 0) {
        // Not UTF-8 (a Latin-1 file, say): the reader (yaml-cpp) takes such bytes as they are, so
        // they are written as they are and read back equal.
        out += s[i++];
        continue;
      }
      const char32_t cp = c.value;
      if (cp == '"')
        out += "\\\"";
      else if (cp == '\\')
        out += "\\\\";
      else if (cp == '\n')
        out += "\\n";
      else if (cp == '\t')
        out += "\\t";
      else if (cp == '\r')
        out += "\\r";
      else if (cp < 0x20 || cp == 0x7F)
        out += fmt::format("\\x{:02X}", static_cast<unsigned>(cp));
      else if ((cp >= 0x80 && cp <= 0x9F) || cp == 0x2028 || cp == 0x2029 || cp == 0xFEFF)
        out += fmt::format("\\u{:04X}", static_cast<unsigned>(cp));
      else
        out += s.substr(i, c.length);
      i += c.length;
    }
    return out + "\"";
  }
  // The source file in the header comment: printable, one line, whatever bytes it holds.
  static std::string comment_text(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size();) {
      const CodePoint c = decode_utf8(s, i);
      if (c.length == 0 || c.value < 0x20 || c.value == 0x7F ||
          (c.value >= 0x80 && c.value <= 0x9F) || c.value == 0x2028 || c.value == 0x2029 ||
          c.value == 0xFEFF) {
        out += '?';
        i += std::max<size_t>(1, c.length);
      } else {
        out += s.substr(i, c.length);
        i += c.length;
      }
    }
    return out;
  }
  // " # 30°" after an angle in radians, for the reader of the file (not read back).
  static std::string degrees_comment(double rad) {
    return fmt::format("  # {:.6g}°", rad * 180.0 / kPi);
  }

  void line(const std::string& s) { out_ += s + "\n"; }
  std::string take() { return std::move(out_); }

 private:
  // [A-Za-z_][A-Za-z0-9_-]* (every scene name) minus the words YAML 1.1 reads as null or a boolean
  // (yaml-cpp reads `null` as a null node, not text).
  static bool is_plain_safe(const std::string& s) {
    if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
    for (const char ch : s)
      if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-')) return false;
    std::string lower;
    for (const char ch : s)
      lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    for (const char* w : {"null", "true", "false", "yes", "no", "on", "off", "y", "n"})
      if (lower == w) return false;
    return true;
  }

  std::string file_;
  std::string out_;
};

bool is_prismatic(const Scene& s, const std::string& joint) {
  const Joint* j = s.find_joint(joint);
  return j && j->type == JointType::Prismatic;
}

void write_points(Writer& w, const std::string& indent, const std::string& key,
                  const std::map<std::string, Vec2>& points, const std::string& field) {
  if (points.empty()) {
    w.line(indent + key + ": {}");
    return;
  }
  w.line(indent + key + ":");
  for (const auto& [name, p] : points)
    w.line(indent + "  " + w.text(name) + ": " + w.vec(p, field + "." + name));
}

void write_mechanism(Writer& w, const Scene& s) {
  write_points(w, "", "ground_points", s.ground_points, "ground_points");
  w.line(s.bodies.empty() ? "bodies: []" : "bodies:");
  for (const auto& b : s.bodies) {
    const std::string f = "bodies." + b.name;
    w.line("  - name: " + w.text(b.name));
    w.line("    mass_kg: " + w.num(b.mass_kg, f + ".mass_kg"));
    w.line("    com_m: " + w.vec(b.com_m, f + ".com_m"));
    w.line("    inertia_kgm2: " + w.num(b.inertia_kgm2, f + ".inertia_kgm2"));
    write_points(w, "    ", "points", b.points, f + ".points");
  }
  w.line(s.joints.empty() ? "joints: []" : "joints:");
  for (const auto& j : s.joints) {
    const std::string f = "joints." + j.name;
    const bool prismatic = j.type == JointType::Prismatic;
    w.line("  - name: " + w.text(j.name));
    w.line(std::string("    type: ") + (prismatic ? "prismatic" : "revolute"));
    w.line("    parent: " + w.text(j.parent));
    w.line("    parent_point: " + w.vec(j.parent_point, f + ".parent_point"));
    w.line("    child: " + w.text(j.child));
    w.line("    child_point: " + w.vec(j.child_point, f + ".child_point"));
    if (prismatic) {
      w.line("    axis: " + w.vec(j.axis, f + ".axis"));
      w.line("    guess_m: " + w.num(j.guess, f + ".guess"));
    } else {
      // Radians: a degree value need not read back to the same double (x·π/180 rounds).
      w.line("    offset_rad: " + w.num(j.offset_rad, f + ".offset_rad") +
             Writer::degrees_comment(j.offset_rad));
      w.line("    guess_rad: " + w.num(j.guess, f + ".guess") + Writer::degrees_comment(j.guess));
    }
  }
  w.line(s.loops.empty() ? "loops: []" : "loops:");
  for (const auto& l : s.loops) {
    const std::string f = "loops." + l.name;
    w.line("  - name: " + w.text(l.name));
    w.line("    body_a: " + w.text(l.body_a));
    w.line("    point_a: " + w.vec(l.point_a, f + ".point_a"));
    w.line("    body_b: " + w.text(l.body_b));
    w.line("    point_b: " + w.vec(l.point_b, f + ".point_b"));
    if (l.branch)
      w.line("    branch: {joint: " + w.text(l.branch->joint) +
             ", sign: " + (l.branch->sign > 0 ? "positive" : "negative") + "}");
  }
  w.line(s.gears.empty() ? "gears: []" : "gears:");
  for (const auto& g : s.gears) {
    const std::string f = "gears." + g.name;
    w.line("  - {name: " + w.text(g.name) + ", driver: " + w.text(g.driver) +
           ", driven: " + w.text(g.driven) + ", ratio: " + w.num(g.ratio, f + ".ratio") + "}");
  }
  w.line("independent: " + w.text(s.independent));
  if (s.independent_range) {
    const bool revolute = !is_prismatic(s, s.independent);
    w.line("independent_range: [" + w.num(s.independent_range->min, "independent_range[0]") + ", " +
           w.num(s.independent_range->max, "independent_range[1]") + "]" +
           (revolute ? fmt::format("  # [{:.6g}°, {:.6g}°]", s.independent_range->min * 180.0 / kPi,
                                   s.independent_range->max * 180.0 / kPi)
                     : ""));
  }
}

void write_profile(Writer& w, const LoadProfile& p, const std::string& f) {
  w.line("    profile:");
  w.line("      of: " + w.text(p.of));
  if (!p.is_table()) {
    auto list = [&](const std::vector<double>& v, const std::string& key) {
      std::string t = "[";
      for (size_t i = 0; i < v.size(); ++i)
        t += (i ? ", " : "") + w.num(v[i], fmt::format("{}.fourier.{}[{}]", f, key, i));
      return t + "]";
    };
    w.line("      fourier: {a0: " + w.num(p.a0, f + ".fourier.a0") + ", a: " + list(p.a, "a") +
           ", b: " + list(p.b, "b") + "}");
    return;
  }
  // Rows in radians, as the profile holds them: the spline is rebuilt from the same knots.
  w.line("      table_rad:  # [angle rad, value per unit amplitude]");
  for (size_t i = 0; i < p.table_theta_rad.size() && i < p.table_value.size(); ++i) {
    const std::string fi = fmt::format("{}.table_rad[{}]", f, i);
    w.line("        - [" + w.num(p.table_theta_rad[i], fi + "[0]") + ", " +
           w.num(p.table_value[i], fi + "[1]") + "]" +
           Writer::degrees_comment(p.table_theta_rad[i]));
  }
}

// The optional rate gate and profile of a drive load (joint torque or point force).
void write_gate_and_profile(Writer& w, const std::optional<RateGate>& gate, const std::optional<LoadProfile>& profile,
                            const std::string& f) {
  if (gate)
    w.line("    active_when: {joint: " + w.text(gate->joint) + ", rate: " + (gate->sign > 0 ? "positive" : "negative") +
           "}");
  if (profile) write_profile(w, *profile, f + ".profile");
}

// Loads by kind (torques, resistances, springs, motors), each kind in scene order: the reader keeps
// one list per kind, so this order reads back to the same lists.
void write_loads(Writer& w, const Scene& s) {
  const bool none = s.joint_torques.empty() && s.resistances.empty() && s.springs.empty() &&
                    s.point_forces.empty() && s.motors.empty();
  w.line(none ? "loads: []" : "loads:");
  for (const auto& t : s.joint_torques) {
    const std::string f = "loads." + t.name;
    w.line("  - type: joint_torque");
    w.line("    name: " + w.text(t.name));
    w.line("    joint: " + w.text(t.joint));
    const bool prismatic = is_prismatic(s, t.joint);
    const std::string key = prismatic ? "force_N" : "torque_Nm";
    w.line("    " + key + ": " + w.num(t.value, f + "." + key) +
           (t.profile ? "  # amplitude of the profile" : ""));
    write_gate_and_profile(w, t.active_when, t.profile, f);
  }
  for (const auto& r : s.resistances) {
    const std::string f = "loads." + r.name;
    const char* law = r.law == ResistanceLaw::Constant  ? "constant"
                      : r.law == ResistanceLaw::Viscous ? "viscous"
                                                        : "quadratic";
    w.line("  - {type: resistance, name: " + w.text(r.name) + ", body: " + w.text(r.body) +
           ", law: " + law + ", coefficient: " + w.num(r.coefficient, f + ".coefficient") + "}");
  }
  for (const auto& sp : s.springs) {
    const std::string f = "loads." + sp.name;
    w.line("  - type: spring");
    w.line("    name: " + w.text(sp.name));
    w.line("    body_a: " + w.text(sp.body_a));
    w.line("    point_a: " + w.vec(sp.point_a, f + ".point_a"));
    w.line("    body_b: " + w.text(sp.body_b));
    w.line("    point_b: " + w.vec(sp.point_b, f + ".point_b"));
    w.line("    stiffness_N_per_m: " + w.num(sp.stiffness_N_per_m, f + ".stiffness_N_per_m"));
    w.line("    rest_length_m: " + w.num(sp.rest_length_m, f + ".rest_length_m"));
  }
  for (const auto& pf : s.point_forces) {
    const std::string f = "loads." + pf.name;
    w.line("  - type: point_force");
    w.line("    name: " + w.text(pf.name));
    w.line("    body_a: " + w.text(pf.body_a));
    w.line("    point_a: " + w.vec(pf.point_a, f + ".point_a"));
    w.line("    body_b: " + w.text(pf.body_b));
    w.line("    point_b: " + w.vec(pf.point_b, f + ".point_b"));
    w.line("    force_N: " + w.num(pf.value, f + ".force_N") + (pf.profile ? "  # amplitude of the profile" : ""));
    write_gate_and_profile(w, pf.active_when, pf.profile, f);
  }
  for (const auto& m : s.motors) {
    const std::string f = "loads." + m.name;
    const bool prismatic = is_prismatic(s, m.joint);
    const std::string stall = prismatic ? "stall_force_N" : "stall_torque_Nm";
    const std::string speed = prismatic ? "no_load_speed_m_s" : "no_load_speed_rad_s";
    w.line("  - {type: motor, name: " + w.text(m.name) + ", joint: " + w.text(m.joint) + ", " +
           stall + ": " + w.num(m.stall_torque, f + "." + stall) + ", " + speed + ": " +
           w.num(m.no_load_speed, f + "." + speed) + "}");
  }
}

void write_outputs(Writer& w, const Scene& s) {
  const Outputs& o = s.outputs;
  auto names = [&](const std::vector<std::string>& v) {
    std::string t = "[";
    for (size_t i = 0; i < v.size(); ++i) t += (i ? ", " : "") + w.text(v[i]);
    return t + "]";
  };
  w.line("outputs:");
  w.line(o.constraint_forces.empty() ? "  constraint_forces: []" : "  constraint_forces:");
  for (const auto& c : o.constraint_forces) {
    const std::string f = "outputs.constraint_forces." + c.name;
    w.line("    - {name: " + w.text(c.name) + ", joint: " + w.text(c.joint) +
           ", direction: " + w.vec(c.direction, f + ".direction") + "}");
  }
  w.line("  bodies: " + names(o.bodies));
  w.line("  joints: " + names(o.joints));
  // `all` stays `all` while the list is what it stands for (every joint, then every loop): it
  // tells the reduced model to leave out the reactions it cannot give rather than refuse them.
  std::vector<std::string> all;
  for (const auto& j : s.joints) all.push_back(j.name);
  for (const auto& l : s.loops) all.push_back(l.name);
  w.line("  reactions: " + (o.reactions_all && o.reactions == all ? std::string("all") : names(o.reactions)));
  w.line(std::string("  shaking: ") + (o.shaking ? "true" : "false"));
}

void write_validation(Writer& w, const Scene& s) {
  const Validation& v = s.validation;
  w.line("validation:");
  w.line("  duration_s: " + w.num(v.duration_s, "validation.duration_s") +
         "  # 0: simulation.duration_s");
  w.line("  reference_tolerance: " +
         w.num(v.reference_tolerance, "validation.reference_tolerance"));
  w.line("  reference_integrator: " + w.text(v.reference_integrator));
  if (!v.note.empty()) w.line("  note: " + w.text(v.note));
  w.line(v.thresholds.empty() ? "  thresholds: []" : "  thresholds:");
  for (size_t i = 0; i < v.thresholds.size(); ++i) {
    const Threshold& t = v.thresholds[i];
    const std::string f = fmt::format("validation.thresholds[{}]", i);
    w.line("    - {quantity: " + w.text(t.quantity) +
           ", grid_deg: " + w.num(t.grid_deg, f + ".grid_deg") +
           (t.interpolation.empty() ? "" : ", interpolation: " + w.text(t.interpolation)) +
           ", max_error: " + w.num(t.max_error, f + ".max_error") + "}");
  }
  // A calibrate block with a zero cadence is refused by the reader (it would silently mean "off"),
  // so an unset calibration is left out; a partly set one is written and refused.
  if (v.calibrate_cadence_Hz != 0.0 || v.calibrate_power_W != 0.0 || !v.calibrate_load.empty()) {
    w.line("  calibrate:");
    w.line("    cadence_Hz: " + w.num(v.calibrate_cadence_Hz, "validation.calibrate.cadence_Hz"));
    if (v.calibrate_power_W != 0.0)
      w.line("    power_W: " + w.num(v.calibrate_power_W, "validation.calibrate.power_W"));
    if (!v.calibrate_load.empty()) w.line("    load: " + w.text(v.calibrate_load));
    if (v.calibrate_grid_given || v.calibrate_grid_deg != 10.0)
      w.line("    grid_deg: " + w.num(v.calibrate_grid_deg, "validation.calibrate.grid_deg"));
  }
  if (!v.compare.empty()) w.line("  compare:");
  for (size_t i = 0; i < v.compare.size(); ++i) {
    const CompareValue& c = v.compare[i];
    const std::string f = fmt::format("validation.compare[{}]", i);
    w.line("    - quantity: " + w.text(c.quantity));
    w.line("      value: " + w.num(c.value, f + ".value"));
    w.line("      unit: " + w.text(c.unit));
    w.line("      source: " + w.text(c.source));
    w.line("      explanation: " + w.text(c.explanation));
  }
}

// The `optimize` block (rdyn optimize's design), shifts in radians so they read back exactly.
void write_optimize(Writer& w, const OptimizeSpec& o) {
  w.line("optimize:");
  if (!o.loads.empty()) {
    w.line("  loads:");
    for (size_t i = 0; i < o.loads.size(); ++i) {
      const auto& d = o.loads[i];
      std::string item = "    - {load: " + w.text(d.load);
      if (!d.same_as.empty())
        item += ", same_as: " + w.text(d.same_as) + ", shift_rad: " +
                w.num(d.shift_rad, fmt::format("optimize.loads[{}].shift_rad", i));
      w.line(item + "}");
    }
  }
  if (!o.of.empty()) w.line("  of: " + w.text(o.of));
  if (!o.force.empty()) w.line("  force: " + w.text(o.force));
  w.line(fmt::format("  harmonics: {}", o.harmonics));
  if (o.max_load > 0) w.line("  max_load: " + w.num(o.max_load, "optimize.max_load"));
  w.line(std::string("  nonnegative: ") + (o.nonnegative ? "true" : "false"));
  w.line("  objective: " + w.text(o.objective));
  if (o.objective == "pnorm") w.line("  p: " + w.num(o.p, "optimize.p"));
}

}  // namespace

std::string scene_to_yaml(const Scene& s) {
  Writer w(s);
  w.line("# Written by rdyn from scene '" + Writer::comment_text(s.name) + "'" +
         (s.source_file.empty() ? "" : " (" + Writer::comment_text(s.source_file) + ")") + ".");
  w.line(
      "# The expanded scene: generators applied, named points resolved, "
      "every value explicit;");
  w.line(
      "# angles in radians (degrees in comments). The original's comments "
      "are not kept.");
  w.line("name: " + w.text(s.name));
  if (!s.description.empty()) w.line("description: " + w.text(s.description));
  write_mechanism(w, s);
  write_loads(w, s);
  w.line("gravity: {enabled: " + std::string(s.gravity.enabled ? "true" : "false") +
         ", g_m_s2: " + w.vec(s.gravity.g_m_s2, "gravity.g_m_s2") + "}");
  write_outputs(w, s);
  w.line("initial: {q: " + w.num(s.initial.q, "initial.q") +
         ", qdot: " + w.num(s.initial.qdot, "initial.qdot") + "}" +
         (is_prismatic(s, s.independent) ? "" : Writer::degrees_comment(s.initial.q)));
  w.line("simulation: {duration_s: " + w.num(s.simulation.duration_s, "simulation.duration_s") +
         ", output_interval_s: " +
         w.num(s.simulation.output_interval_s, "simulation.output_interval_s") +
         ", tolerance: " + w.num(s.simulation.tolerance, "simulation.tolerance") + "}");
  write_validation(w, s);
  if (s.optimize) write_optimize(w, *s.optimize);
  return w.take();
}

std::string scene_to_yaml_checked(const Scene& s) {
  const std::string yaml = scene_to_yaml(s);
  const Scene back = parse_scene(yaml, s.source_file);
  if (scene_hash(back) != scene_hash(s))
    throw NumericalError(
        fmt::format("scene '{}' does not read back as written (its scene hash changes from {} to "
                    "{}): it holds a "
                    "value the scene format cannot express",
                    s.name, scene_hash_hex(scene_hash(s)), scene_hash_hex(scene_hash(back))));
  if (scene_to_yaml(back) != yaml)
    throw NumericalError(fmt::format(
        "scene '{}' does not read back as written (writing it again gives another text)", s.name));
  return yaml;
}

}  // namespace rdyn::models
