// Scene hash: every field a reduced table depends on changes it; nothing else does.
#include "models/scene_hash.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>
#include <set>

#include "models/scene_yaml.hpp"

namespace rdyn::models {
namespace {

// The bicycle (two loops, gated torques, a resistance, a constraint force) plus one spring,
// one motor and one gear-free ground point, so every kind of field is present.
Scene full_scene() {
  Scene s = load_scene("bicycle");
  s.springs.push_back({"spring", kGround, {0.1, 0.2}, s.bodies[0].name, {0.0, 0.0}, 100.0, 0.3});
  s.motors.push_back({"motor", s.independent, 3.0, 60.0});
  s.ground_points["extra"] = {0.5, 0.5};
  return s;
}

std::string another_joint(const Scene& s, const std::string& name) {
  return s.joints[0].name == name ? s.joints[1].name : s.joints[0].name;
}

struct Mutation {
  const char* field;
  std::function<void(Scene&)> apply;
};

// The canonical text's numbers against glibc's own "%a" (what the text was written with before):
// special values, signs, both ends of the exponent range, subnormals, fractions with and without
// trailing zero digits, and 200 000 random bit patterns.
TEST(SceneHash, HexDoubleAsPrintfA) {
  auto printf_a = [](double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return std::string(buf);
  };
  auto ours = [](double v) {
    std::string s = "x";  // appends to what is there
    append_hex_double(s, v);
    return s.substr(1);
  };
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> values{0.0, -0.0, 1.0, -1.0, 2.0, 0.5, 3.0, 0.1, -0.3, 1e300, 1e-300, 9.81, 1.5, 0.75,
                             std::numeric_limits<double>::max(), std::numeric_limits<double>::min(),
                             std::numeric_limits<double>::denorm_min(), -std::numeric_limits<double>::denorm_min(),
                             std::numeric_limits<double>::min() / 3, std::numeric_limits<double>::epsilon(),
                             1 + std::numeric_limits<double>::epsilon(), inf, -inf,
                             std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN()};
  for (double v : values) EXPECT_EQ(ours(v), printf_a(v)) << printf_a(v);
  std::mt19937_64 rng(28);
  for (int i = 0; i < 200000; ++i) {
    std::uint64_t bits = rng();
    if (i % 4 == 1) bits &= ~(std::uint64_t{0x7ff} << 52);  // subnormals
    if (i % 4 == 2) bits &= ~((std::uint64_t{1} << (rng() % 52)) - 1);  // trailing zero digits
    double v;
    std::memcpy(&v, &bits, sizeof v);
    ASSERT_EQ(ours(v), printf_a(v)) << i;
  }
}

TEST(SceneHash, IsDeterministicAndSixteenHexDigits) {
  const Scene a = full_scene(), b = full_scene();
  EXPECT_EQ(scene_hash(a), scene_hash(b));
  EXPECT_EQ(canonical_scene_text(a), canonical_scene_text(b));
  EXPECT_EQ(scene_hash_hex(0x0123456789abcdefull), "0123456789abcdef");
  EXPECT_EQ(scene_hash_hex(scene_hash(a)).size(), 16u);
}

TEST(SceneHash, KnownFnv1aValues) {
  // FNV-1a 64 of the empty string is the offset basis; of "a" it is af63dc4c8601ec8c
  // (draft-eastlake-fnv test vectors). The hash of a scene is FNV-1a of its canonical text,
  // so check that relation on the real text instead of re-implementing it.
  const std::string text = canonical_scene_text(full_scene());
  ASSERT_FALSE(text.empty());
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  EXPECT_EQ(scene_hash(full_scene()), h);
  std::uint64_t a = 14695981039346656037ull;
  a = (a ^ static_cast<unsigned char>('a')) * 1099511628211ull;
  EXPECT_EQ(a, 0xaf63dc4c8601ec8cull);
}

TEST(SceneHash, ChangesWithEveryFieldTheTableDependsOn) {
  const std::vector<Mutation> included = {
      {"bodies[0].name", [](Scene& s) { s.bodies[0].name += "x"; }},
      {"bodies[0].mass_kg", [](Scene& s) { s.bodies[0].mass_kg *= 1 + 1e-15; }},
      {"bodies[1].com_m.x", [](Scene& s) { s.bodies[1].com_m.x += 1e-9; }},
      {"bodies[1].com_m.y", [](Scene& s) { s.bodies[1].com_m.y += 1e-9; }},
      {"bodies[2].inertia_kgm2", [](Scene& s) { s.bodies[2].inertia_kgm2 *= 2; }},
      {"bodies[0].points", [](Scene& s) { s.bodies[0].points.begin()->second.x += 1e-6; }},
      {"bodies[0].points (new)", [](Scene& s) { s.bodies[0].points["zz"] = {0, 0}; }},
      {"body order", [](Scene& s) { std::swap(s.bodies[0], s.bodies[1]); }},
      {"ground_points", [](Scene& s) { s.ground_points["extra"].y = 0.25; }},
      {"joints[1].type", [](Scene& s) { s.joints[1].type = JointType::Prismatic; }},
      {"joints[1].parent", [](Scene& s) { s.joints[1].parent += "x"; }},
      {"joints[1].child", [](Scene& s) { s.joints[1].child += "x"; }},
      {"joints[1].parent_point", [](Scene& s) { s.joints[1].parent_point.x += 1e-6; }},
      {"joints[1].child_point", [](Scene& s) { s.joints[1].child_point.y += 1e-6; }},
      {"joints[1].axis", [](Scene& s) { s.joints[1].axis.y = 1.0; }},
      {"joints[1].offset_rad", [](Scene& s) { s.joints[1].offset_rad += 0.1; }},
      {"joints[2].guess (branch)", [](Scene& s) { s.joints[2].guess = -s.joints[2].guess - 1.0; }},
      {"joints[0].name", [](Scene& s) { s.joints[0].name += "x"; }},
      {"loops[0].point_a", [](Scene& s) { s.loops[0].point_a.x += 1e-6; }},
      {"loops[0].body_b", [](Scene& s) { s.loops[0].body_b += "x"; }},
      {"loops (removed)", [](Scene& s) { s.loops.pop_back(); }},
      {"gears[0].ratio", [](Scene& s) { s.gears.at(0).ratio *= -1; }},
      {"independent", [](Scene& s) { s.independent = s.joints[1].name; }},
      {"gravity.enabled", [](Scene& s) { s.gravity.enabled = !s.gravity.enabled; }},
      {"gravity.g_m_s2", [](Scene& s) { s.gravity.g_m_s2.y = -9.80665; }},
      {"outputs.constraint_forces.name", [](Scene& s) { s.outputs.constraint_forces[0].name += "x"; }},
      {"outputs.constraint_forces.joint", [](Scene& s) { s.outputs.constraint_forces[0].joint += "x"; }},
      {"outputs.constraint_forces.direction", [](Scene& s) { s.outputs.constraint_forces[0].direction.x += 1e-3; }},
      {"outputs.constraint_forces (removed)", [](Scene& s) { s.outputs.constraint_forces.clear(); }},
      {"initial.q", [](Scene& s) { s.initial.q += 1e-12; }},
      {"springs.stiffness", [](Scene& s) { s.springs[0].stiffness_N_per_m = 101.0; }},
      {"springs.rest_length", [](Scene& s) { s.springs[0].rest_length_m = 0.31; }},
      {"springs.point_a", [](Scene& s) { s.springs[0].point_a.x = 0.11; }},
      {"springs.body_b", [](Scene& s) { s.springs[0].body_b = s.bodies[1].name; }},
      {"loads torque joint", [](Scene& s) { s.joint_torques.at(0).joint = another_joint(s, s.joint_torques[0].joint); }},
      {"loads torque gate joint",
       [](Scene& s) { s.joint_torques.at(0).active_when->joint = another_joint(s, s.joint_torques[0].active_when->joint); }},
      {"loads torque gate sign", [](Scene& s) { s.joint_torques.at(0).active_when->sign *= -1; }},
      {"loads torque gate removed", [](Scene& s) { s.joint_torques.at(0).active_when.reset(); }},
      {"loads torque added", [](Scene& s) { s.joint_torques.push_back({"t", s.independent, 1.0, {}}); }},
      {"loads motor joint", [](Scene& s) { s.motors[0].joint = s.joints[1].name; }},
      {"loads resistance body", [](Scene& s) { s.resistances.at(0).body = s.bodies[0].name + "x"; }},
  };
  const Scene base = full_scene();
  ASSERT_FALSE(base.gears.empty());
  ASSERT_FALSE(base.joint_torques.empty());
  ASSERT_TRUE(base.joint_torques[0].active_when);
  ASSERT_FALSE(base.resistances.empty());
  ASSERT_FALSE(base.outputs.constraint_forces.empty());
  const std::uint64_t h0 = scene_hash(base);
  std::set<std::uint64_t> seen{h0};
  for (const auto& m : included) {
    Scene s = full_scene();
    m.apply(s);
    const std::uint64_t h = scene_hash(s);
    EXPECT_NE(h, h0) << m.field;
    EXPECT_TRUE(seen.insert(h).second) << m.field << " collides with another mutation";
  }
}

TEST(SceneHash, IgnoresWhatNoTableColumnDependsOn) {
  const std::vector<Mutation> excluded = {
      {"name", [](Scene& s) { s.name = "other"; }},
      {"description", [](Scene& s) { s.description = "other"; }},
      {"source_file", [](Scene& s) { s.source_file = "/elsewhere.yaml"; }},
      {"simulation.duration_s", [](Scene& s) { s.simulation.duration_s = 99; }},
      {"simulation.output_interval_s", [](Scene& s) { s.simulation.output_interval_s = 0.5; }},
      {"simulation.tolerance", [](Scene& s) { s.simulation.tolerance = 1e-3; }},
      {"validation", [](Scene& s) {
         s.validation.duration_s = 3;
         s.validation.reference_tolerance = 1e-6;
         s.validation.thresholds.clear();
         s.validation.note = "x";
       }},
      {"initial.qdot", [](Scene& s) { s.initial.qdot = -3.0; }},
      {"outputs.bodies", [](Scene& s) { s.outputs.bodies.push_back(s.bodies[0].name); }},
      {"torque value", [](Scene& s) { s.joint_torques.at(0).value = 12.5; }},
      {"torque name", [](Scene& s) { s.joint_torques.at(0).name = "renamed"; }},
      {"resistance coefficient and law", [](Scene& s) {
         s.resistances.at(0).coefficient = 7.0;
         s.resistances.at(0).law = ResistanceLaw::Quadratic;
       }},
      {"motor values", [](Scene& s) { s.motors[0].stall_torque = 4, s.motors[0].no_load_speed = 70; }},
      {"spring name", [](Scene& s) { s.springs[0].name = "renamed"; }},
      {"-0 for +0", [](Scene& s) { s.gravity.g_m_s2.x = -0.0; }},
  };
  const std::uint64_t h0 = scene_hash(full_scene());
  ASSERT_EQ(full_scene().gravity.g_m_s2.x, 0.0);
  for (const auto& m : excluded) {
    Scene s = full_scene();
    m.apply(s);
    EXPECT_EQ(scene_hash(s), h0) << m.field;
  }
}

TEST(SceneHash, ShippedScenesDifferAndSameMechanismsAgree) {
  // The fourbar, slider-crank and bicycle are different mechanisms; coarse-grid is the
  // bicycle's mechanism with only its validation grid changed, so a bicycle table fits it.
  const auto bicycle = scene_hash(load_scene("bicycle"));
  EXPECT_NE(bicycle, scene_hash(load_scene("fourbar")));
  EXPECT_NE(bicycle, scene_hash(load_scene("slider-crank")));
  EXPECT_NE(scene_hash(load_scene("fourbar")), scene_hash(load_scene("slider-crank")));
  EXPECT_EQ(bicycle, scene_hash(load_scene(RDYN_SCENES "/hard/coarse-grid.yaml")));
}

}  // namespace
}  // namespace rdyn::models
