#include "models/scene_hash.hpp"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace rdyn::models {

namespace {

// Appends tagged fields to one canonical text: "tag=value;" with exact doubles and
// length-prefixed strings, so no two different scenes serialize alike. Appended in place
// (append_hex_double, no snprintf or temporary strings): a sweep over a mechanism hashes each
// case's scene 4 times, and snprintf's "%a" with the tags' temporaries was ~1.1 M instructions
// of a ~30 M case (issue #28).
class Canon {
 public:
  Canon() { text_.reserve(4096); }
  Canon& num(const char* tag, double v) { return num(tag, "", v); }
  Canon& integer(const char* tag, long v) { return put(tag, std::to_string(v)); }
  Canon& str(const char* tag, const std::string& s) {
    text_ += tag;
    text_ += '=';
    text_ += std::to_string(s.size());
    text_ += ':';
    text_ += s;
    text_ += ';';
    return *this;
  }
  Canon& vec(const char* tag, const Vec2& v) { return num(tag, ".x", v.x).num(tag, ".y", v.y); }
  Canon& open(const char* section, size_t count) { return put(section, "[" + std::to_string(count)); }
  const std::string& text() const { return text_; }

 private:
  Canon& num(const char* tag, const char* suffix, double v) {
    if (v == 0.0) v = 0.0;  // −0 and +0 describe the same scene
    text_ += tag;
    text_ += suffix;
    text_ += '=';
    append_hex_double(text_, v);
    text_ += ';';
    return *this;
  }
  Canon& put(const char* tag, const std::string& value) {
    text_ += tag;
    text_ += '=';
    text_ += value;
    text_ += ';';
    return *this;
  }
  std::string text_;
};

// A load profile's shape (what extraction tabulates as tau_<load>).
void put_profile(Canon& c, const LoadProfile& p) {
  c.str("profile_of", p.of).num("a0", p.a0);
  for (double v : p.a) c.num("a", v);
  for (double v : p.b) c.num("b", v);
  for (size_t i = 0; i < p.table_theta_rad.size(); ++i) c.num("row_deg", p.table_theta_rad[i]).num("row", p.table_value[i]);
}

}  // namespace

void append_hex_double(std::string& out, double v) {
  if (std::isnan(v)) {
    out += std::signbit(v) ? "-nan" : "nan";
    return;
  }
  if (std::signbit(v)) out += '-';
  if (std::isinf(v)) {
    out += "inf";
    return;
  }
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  const std::uint64_t fraction = bits & ((std::uint64_t{1} << 52) - 1);
  const int biased = static_cast<int>((bits >> 52) & 0x7ff);
  if (biased == 0 && fraction == 0) {
    out += "0x0p+0";
    return;
  }
  // glibc writes a subnormal as 0x0.<fraction>p-1022, a normal number as 0x1.<fraction>p<e>.
  out += biased == 0 ? "0x0" : "0x1";
  if (fraction != 0) {
    static constexpr char kDigits[] = "0123456789abcdef";
    char digits[13];
    int n = 0;
    for (int k = 12; k >= 0; --k) digits[n++] = kDigits[(fraction >> (4 * k)) & 0xf];
    while (digits[n - 1] == '0') --n;  // trailing zeros dropped, as "%a" does
    out += '.';
    out.append(digits, static_cast<size_t>(n));
  }
  const int exponent = biased == 0 ? -1022 : biased - 1023;
  out += exponent < 0 ? "p-" : "p+";
  out += std::to_string(exponent < 0 ? -exponent : exponent);
}

std::string canonical_scene_text(const Scene& s) {
  Canon c;
  c.str("format", "rdyn-scene-hash v1");
  c.open("bodies", s.bodies.size());
  for (const auto& b : s.bodies) {
    c.str("name", b.name).num("mass", b.mass_kg).vec("com", b.com_m).num("inertia", b.inertia_kgm2);
    c.open("points", b.points.size());
    for (const auto& [name, p] : b.points) c.str("point", name).vec("p", p);
  }
  c.open("ground_points", s.ground_points.size());
  for (const auto& [name, p] : s.ground_points) c.str("point", name).vec("p", p);
  c.open("joints", s.joints.size());
  for (const auto& j : s.joints) {
    c.str("name", j.name).integer("type", j.type == JointType::Revolute ? 0 : 1);
    c.str("parent", j.parent).str("child", j.child).vec("parent_point", j.parent_point);
    c.vec("child_point", j.child_point).vec("axis", j.axis).num("offset", j.offset_rad).num("guess", j.guess);
  }
  c.open("loops", s.loops.size());
  for (const auto& l : s.loops)
    c.str("name", l.name).str("a", l.body_a).vec("pa", l.point_a).str("b", l.body_b).vec("pb", l.point_b);
  c.open("gears", s.gears.size());
  for (const auto& g : s.gears)
    c.str("name", g.name).str("driver", g.driver).str("driven", g.driven).num("ratio", g.ratio);
  c.str("independent", s.independent);
  // Only when declared, so the hashes of scenes without a range stay what they were.
  if (s.independent_range) c.num("range_min", s.independent_range->min).num("range_max", s.independent_range->max);
  c.integer("gravity", s.gravity.enabled ? 1 : 0).vec("g", s.gravity.g_m_s2);
  c.open("constraint_forces", s.outputs.constraint_forces.size());
  for (const auto& f : s.outputs.constraint_forces) c.str("name", f.name).str("joint", f.joint).vec("dir", f.direction);
  c.num("initial_q", s.initial.q);
  c.open("springs", s.springs.size());
  for (const auto& sp : s.springs) {
    c.str("a", sp.body_a).vec("pa", sp.point_a).str("b", sp.body_b).vec("pb", sp.point_b);
    c.num("k", sp.stiffness_N_per_m).num("L0", sp.rest_length_m);
  }
  c.open("torques", s.joint_torques.size());
  for (const auto& t : s.joint_torques) {
    c.str("joint", t.joint).integer("gated", t.active_when ? 1 : 0);
    if (t.active_when) c.str("gate_joint", t.active_when->joint).integer("gate_sign", t.active_when->sign);
    if (t.profile) put_profile(c, *t.profile);  // its shape is tabulated (the amplitude, t.value, is not)
  }
  // Only when present, so the hashes of scenes without point forces stay what they were. The
  // geometry, gate and profile shape are tabulated (Qpf_/tau_ columns); the tension, pf.value,
  // is not, so a calibration rescales it without re-extraction.
  if (!s.point_forces.empty()) {
    c.open("point_forces", s.point_forces.size());
    for (const auto& pf : s.point_forces) {
      c.str("name", pf.name).str("a", pf.body_a).vec("pa", pf.point_a).str("b", pf.body_b).vec("pb", pf.point_b);
      c.integer("gated", pf.active_when ? 1 : 0);
      if (pf.active_when) c.str("gate_joint", pf.active_when->joint).integer("gate_sign", pf.active_when->sign);
      if (pf.profile) put_profile(c, *pf.profile);
    }
  }
  c.open("motors", s.motors.size());
  for (const auto& m : s.motors) c.str("joint", m.joint);
  c.open("resistances", s.resistances.size());
  for (const auto& r : s.resistances) c.str("body", r.body);
  return c.text();
}

std::uint64_t fnv1a64(const std::string& text) {
  std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64-bit offset basis
  for (const unsigned char ch : text) {
    h ^= ch;
    h *= 1099511628211ull;  // FNV 64-bit prime
  }
  return h;
}

std::uint64_t scene_hash(const Scene& scene) { return fnv1a64(canonical_scene_text(scene)); }

std::string scene_hash_hex(std::uint64_t hash) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(hash));
  return buf;
}

}  // namespace rdyn::models
