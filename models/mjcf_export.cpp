#include "models/mjcf_export.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "models/pose.hpp"

namespace rdyn::models {

namespace {

// Numbers round-trip exactly (17 significant digits).
std::string num(double x) { return fmt::format("{:.17g}", x); }
std::string vec3(Vec2 p) { return num(p.x) + " " + num(p.y) + " 0"; }

bool is_dropped_control(char c) {
  const auto u = static_cast<unsigned char>(c);
  return (u < 0x20 && c != '\t' && c != '\n' && c != '\r') || u == 0x7f;
}

Vec2 rotate(double a, Vec2 p) {
  return {std::cos(a) * p.x - std::sin(a) * p.y, std::sin(a) * p.x + std::cos(a) * p.y};
}

const char* law_name(ResistanceLaw law) {
  switch (law) {
    case ResistanceLaw::Constant: return "constant (T = -c0 sgn w)";
    case ResistanceLaw::Viscous: return "viscous (T = -c1 w)";
    case ResistanceLaw::Quadratic: return "quadratic (T = -c2 w |w|)";
  }
  return "";
}

void check_options(const Scene& scene, const MjcfOptions& o) {
  auto bad = [&](const std::string& field, const std::string& why) {
    throw SceneError(scene.source_file, 0, field, why);
  };
  // MJCF's ground is the body "world": a scene body of that name would be a second one.
  if (scene.find_body("world"))
    bad("bodies.world.name", "'world' is MJCF's name for ground; rename the body to export the scene as MJCF");
  if (!o.reference_q.empty() && o.reference_q.size() != scene.joints.size())
    bad("reference_q", fmt::format("{} coordinates for {} joints", o.reference_q.size(), scene.joints.size()));
  for (double q : o.reference_q)
    if (!std::isfinite(q)) bad("reference_q", "a coordinate is not finite");
  if (!(std::isfinite(o.timestep_s) && o.timestep_s > 0)) bad("timestep", fmt::format("{} s must be > 0", o.timestep_s));
  if (o.integrator != "Euler" && o.integrator != "RK4") bad("integrator", "'" + o.integrator + "' (Euler, RK4)");
  if (!(std::isfinite(o.timeconst_s) && o.timeconst_s >= 0)) bad("timeconst", "must be ≥ 0");
  if (!(std::isfinite(o.dampratio) && o.dampratio > 0)) bad("dampratio", "must be > 0");
  if (!(o.impedance > 0 && o.impedance < 1)) bad("impedance", "must be in (0, 1)");
}

// Writes the MJCF document; one function per part.
class Writer {
 public:
  Writer(const Scene& s, const MjcfOptions& o) : s_(s), o_(o) {
    q_ref_ = o.reference_q;
    if (q_ref_.empty())
      for (const auto& j : s.joints) q_ref_.push_back(j.guess);
    extra_Izz_.assign(s.bodies.size(), 0.0);
    folded_body_.assign(s.bodies.size(), false);
    folded_gear_.assign(s.gears.size(), false);
    if (o.fold_geared_bodies)
      for (const auto& f : calc_gear_folds(s)) {
        folded_gear_[f.gear] = true;
        folded_body_[f.body] = true;
        extra_Izz_[f.driver_body] += f.moved_inertia_kgm2;
      }
  }

  std::string document() {
    out_ += fmt::format("<mujoco model=\"{}\">\n", xml_escape(s_.name));
    loads_comment();
    const double timeconst = o_.timeconst_s > 0 ? o_.timeconst_s : 2 * o_.timestep_s;
    out_ += "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n";
    const Vec2 g = s_.gravity.enabled ? s_.gravity.g_m_s2 : Vec2{0, 0};
    out_ += fmt::format("  <option timestep=\"{}\" integrator=\"{}\" gravity=\"{}\">\n", num(o_.timestep_s),
                        o_.integrator, vec3(g));
    out_ += "    <flag contact=\"disable\"/>\n  </option>\n";
    // Room for every equality row: 3 per connect, 1 per joint coupling.
    out_ += fmt::format("  <size njmax=\"{}\" nconmax=\"1\"/>\n", 3 * s_.loops.size() + s_.gears.size() + 8);
    out_ += fmt::format("  <default>\n    <equality solref=\"{} {}\" solimp=\"{} {} 0.001\"/>\n  </default>\n",
                        num(timeconst), num(o_.dampratio), num(o_.impedance), num(o_.impedance));
    out_ += "  <worldbody>\n";
    if (o_.visual_geoms)
      for (const auto& p : calc_body_points(s_, kGround)) out_ += "    " + sphere(p) + "\n";
    children_of(kGround, 2);
    out_ += "  </worldbody>\n";
    equalities();
    out_ += "</mujoco>\n";
    return out_;
  }

 private:
  // The loads MJCF cannot hold, and how the runner applies them.
  void loads_comment() {
    std::string c = "Exported by `rdyn export-mjcf` from scene '" + s_.name + "'";
    if (!s_.source_file.empty()) c += " (" + s_.source_file + ")";
    c += ".\n";
    if (!s_.description.empty()) c += s_.description + "\n";
    c += "Planar: every hinge turns about z, every slide stays in the x-y plane; a joint's qpos is the scene's\n"
         "coordinate (its `ref` is the coordinate at which the bodies are written). SI units, radians.\n"
         "Out-of-plane inertias Ixx = Iyy = Izz/2 (a planar lamina); they do no work in planar motion.\n";
    for (size_t g = 0; g < s_.gears.size(); ++g)
      if (folded_gear_[g])
        c += fmt::format("Gear '{}': body '{}' folded into the child of joint '{}' (Izz += r^2 I, r = {}).\n",
                         s_.gears[g].name, s_.find_joint(s_.gears[g].driven)->child, s_.gears[g].driver,
                         num(s_.gears[g].ratio));
    c += fmt::format("Independent coordinate: joint '{}', initial q = {}, qdot = {}.\n", s_.independent,
                     num(s_.initial.q), num(s_.initial.qdot));
    const bool any = !s_.joint_torques.empty() || !s_.resistances.empty() || !s_.motors.empty() ||
                     !s_.springs.empty() || !s_.point_forces.empty();
    if (any)
      c += "Loads MJCF cannot express, applied at every evaluation by rdyn's runner (engine/mujoco_peer.cpp)\n"
           "with the formulas of the full model (engine/scene_loads.cpp):\n";
    for (const auto& t : s_.joint_torques) {
      c += fmt::format("  joint_torque '{}': {} on joint '{}' (qfrc_applied)", t.name, num(t.value), t.joint);
      if (t.active_when)
        c += fmt::format(", only while joint '{}' turns {}", t.active_when->joint,
                         t.active_when->sign > 0 ? "positively" : "negatively");
      c += "\n";
    }
    for (const auto& r : s_.resistances)
      c += fmt::format("  resistance '{}': {} on body '{}', coefficient {} (xfrc_applied torque)\n", r.name,
                       law_name(r.law), r.body, num(r.coefficient));
    for (const auto& m : s_.motors)
      c += fmt::format("  motor '{}' on joint '{}': tau = {} (1 - rate / {}) (qfrc_applied)\n", m.name, m.joint,
                       num(m.stall_torque), num(m.no_load_speed));
    for (const auto& sp : s_.springs)
      c += fmt::format("  spring '{}': {} N/m, rest length {} m, between {} [{}] and {} [{}] (xfrc_applied)\n",
                       sp.name, num(sp.stiffness_N_per_m), num(sp.rest_length_m), sp.body_a, vec3(sp.point_a),
                       sp.body_b, vec3(sp.point_b));
    for (const auto& pf : s_.point_forces) {
      c += fmt::format("  point_force '{}': tension {} N{} along the line between {} [{}] and {} [{}], pulling the "
                       "points together (xfrc_applied)",
                       pf.name, num(pf.value), pf.profile ? " x profile of joint '" + pf.profile->of + "'" : "",
                       pf.body_a, vec3(pf.point_a), pf.body_b, vec3(pf.point_b));
      if (pf.active_when)
        c += fmt::format(", only while joint '{}' turns {}", pf.active_when->joint,
                         pf.active_when->sign > 0 ? "positively" : "negatively");
      c += "\n";
    }
    for (const auto& f : s_.outputs.constraint_forces)
      c += fmt::format("Requested constraint force '{}': reaction of joint '{}' on its child along [{}] (child "
                       "frame).\n",
                       f.name, f.joint, vec3(f.direction));
    out_ += "  <!--\n" + xml_comment_text(c) + "  -->\n";
  }

  // The bodies hanging from `parent` through their tree joints, nested.
  void children_of(const std::string& parent, int depth) {
    const std::string pad(2 * depth, ' ');
    for (size_t j = 0; j < s_.joints.size(); ++j) {
      const auto& jt = s_.joints[j];
      if (jt.parent != parent) continue;
      const int b = s_.body_index(jt.child);
      if (folded_body_[b]) continue;
      const auto& body = s_.bodies[b];
      const double q = q_ref_[j];
      // Child frame in the parent frame at the reference coordinate: the joint's points coincide.
      double angle = 0.0;
      Vec2 pos;
      if (jt.type == JointType::Revolute) {
        angle = jt.offset_rad + q;
        const Vec2 c = rotate(angle, jt.child_point);
        pos = {jt.parent_point.x - c.x, jt.parent_point.y - c.y};
      } else {
        const double n = std::hypot(jt.axis.x, jt.axis.y);
        pos = {jt.parent_point.x + jt.axis.x / n * q - jt.child_point.x,
               jt.parent_point.y + jt.axis.y / n * q - jt.child_point.y};
      }
      out_ += fmt::format("{}<body name=\"{}\" pos=\"{}\" quat=\"{} 0 0 {}\">\n", pad, xml_escape(body.name), vec3(pos),
                          num(std::cos(angle / 2)), num(std::sin(angle / 2)));
      if (jt.type == JointType::Revolute) {
        out_ += fmt::format("{}  <joint name=\"{}\" type=\"hinge\" pos=\"{}\" axis=\"0 0 1\" ref=\"{}\"/>\n", pad,
                            xml_escape(jt.name), vec3(jt.child_point), num(q));
      } else {
        // The child does not turn relative to its parent, so the axis is the same in both frames.
        out_ += fmt::format("{}  <joint name=\"{}\" type=\"slide\" pos=\"{}\" axis=\"{}\" ref=\"{}\"/>\n", pad,
                            xml_escape(jt.name), vec3(jt.child_point), vec3(jt.axis), num(q));
      }
      const double Izz = body.inertia_kgm2 + extra_Izz_[b];
      out_ += fmt::format("{}  <inertial pos=\"{}\" mass=\"{}\" diaginertia=\"{} {} {}\"/>\n", pad, vec3(body.com_m),
                          num(body.mass_kg), num(Izz / 2), num(Izz / 2), num(Izz));
      if (o_.visual_geoms) capsules(body, pad + "  ");
      children_of(body.name, depth + 1);
      out_ += pad + "</body>\n";
    }
  }

  // Visual geoms (MjcfOptions::visual_geoms): one capsule per side of the body's outline (a bar:
  // one; a polygon: closed), a sphere for a body with a single point; in the body frame, which
  // is the scene body's frame (pos/quat above). Radius: geom_radius_, a fixed fraction of the
  // mechanism's size.
  void capsules(const Body& body, const std::string& pad) {
    const auto pts = calc_body_outline(s_, body.name);
    const size_t n = pts.size();
    int drawn = 0;
    for (size_t i = 0; n >= 2 && i < (n == 2 ? 1 : n); ++i) {
      const Vec2 a = pts[i], b = pts[(i + 1) % n];
      if (std::hypot(b.x - a.x, b.y - a.y) < kMinCapsule_m) continue;  // MuJoCo refuses a zero-length fromto
      ++drawn;
      out_ += fmt::format("{}<geom type=\"capsule\" fromto=\"{} {}\" size=\"{}\" contype=\"0\" conaffinity=\"0\" "
                          "rgba=\"0.36 0.68 0.89 1\"/>\n",
                          pad, vec3(a), vec3(b), num(geom_radius()));
    }
    if (drawn == 0) out_ += pad + sphere(n >= 1 ? pts[0] : body.com_m) + "\n";
  }
  static constexpr double kMinCapsule_m = 1e-9;
  std::string sphere(Vec2 p) const {
    return fmt::format("<geom type=\"sphere\" pos=\"{}\" size=\"{}\" contype=\"0\" conaffinity=\"0\" "
                       "rgba=\"0.5 0.5 0.5 1\"/>",
                       vec3(p), num(1.5 * geom_radius()));
  }
  // 1.5 % of the largest distance of a body or ground point from its frame's origin (at least
  // 1 mm): thin bars at any scale.
  double geom_radius() const {
    double r = 1e-3;
    for (const auto& b : s_.bodies)
      for (const auto& p : calc_body_points(s_, b.name)) r = std::max(r, std::hypot(p.x, p.y));
    for (const auto& p : calc_body_points(s_, kGround)) r = std::max(r, std::hypot(p.x, p.y));
    return 0.015 * r;
  }

  void equalities() {
    bool any = !s_.loops.empty();
    for (bool f : folded_gear_) any |= !f;
    if (!any) return;
    out_ += "  <equality>\n";
    for (const auto& l : s_.loops) {
      // MJCF's connect: an anchor on body1; body2's point is where that anchor sits in the
      // configuration written above (closed at the reference coordinates). Ground is "world".
      const bool a_ground = l.body_a == kGround;
      const std::string& b1 = a_ground ? l.body_b : l.body_a;
      const std::string& b2 = a_ground ? l.body_a : l.body_b;
      out_ += fmt::format("    <connect name=\"loop_{}\" body1=\"{}\" body2=\"{}\" anchor=\"{}\"/>\n",
                          xml_escape(l.name), xml_escape(b1), b2 == kGround ? "world" : xml_escape(b2),
                          vec3(a_ground ? l.point_b : l.point_a));
    }
    for (size_t g = 0; g < s_.gears.size(); ++g) {
      if (folded_gear_[g]) continue;
      const auto& gear = s_.gears[g];
      const int jr = s_.joint_index(gear.driver), jd = s_.joint_index(gear.driven);
      // Scene: q_driven = r·q_driver + c, c = guess_driven − r·guess_driver (models/gear_fold.hpp).
      // MJCF: y − y0 = a0 + a1 (x − x0), y = joint1 (driven), x = joint2 (driver), *0 their refs.
      const double c = calc_gear_offset(s_, gear);
      const double a0 = gear.ratio * q_ref_[jr] + c - q_ref_[jd];
      out_ += fmt::format("    <joint name=\"gear_{}\" joint1=\"{}\" joint2=\"{}\" polycoef=\"{} {} 0 0 0\"/>\n",
                          xml_escape(gear.name), xml_escape(gear.driven), xml_escape(gear.driver), num(a0),
                          num(gear.ratio));
    }
    out_ += "  </equality>\n";
  }

  const Scene& s_;
  const MjcfOptions& o_;
  std::vector<double> q_ref_, extra_Izz_;
  std::vector<bool> folded_body_, folded_gear_;
  std::string out_;
};

}  // namespace

std::string export_mjcf(const Scene& scene, const MjcfOptions& options) {
  check_options(scene, options);
  return Writer(scene, options).document();
}

std::string xml_escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (!is_dropped_control(c)) out += c;
    }
  }
  return out;
}

std::string xml_comment_text(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (is_dropped_control(c)) continue;
    if (c == '-' && !out.empty() && out.back() == '-') out += ' ';  // "--" may not appear in a comment
    out += c;
  }
  if (!out.empty() && out.back() == '-') out += ' ';  // nor may the comment end in "-" before "-->"
  return out;
}

}  // namespace rdyn::models
