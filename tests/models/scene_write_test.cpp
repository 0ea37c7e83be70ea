// Writing a scene as YAML: parse_scene(scene_to_yaml(s)) equals s field by field, bit for bit, for
// every shipped scene, the test scenes, scenes changed in code and hostile text.
#include "models/scene_write.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>

#include "models/scene_hash.hpp"
#include "models/scene_yaml.hpp"
#include "tests/engine/test_scenes.hpp"

namespace rdyn::models {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Every field of a scene as text, doubles as C99 hex floats (exact, −0 kept), strings
// length-prefixed: two scenes are equal field by field iff their dumps are. Written here,
// independently of the writer, and checked against a mutation of each field below.
class Dump {
 public:
  Dump& num(const char* tag, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return put(tag, buf);
  }
  Dump& str(const char* tag, const std::string& s) {
    return put(tag, fmt::format("{}:{}", s.size(), s));
  }
  Dump& vec(const char* tag, const Vec2& v) { return num(tag, v.x).num(tag, v.y); }
  Dump& integer(const char* tag, long v) { return put(tag, std::to_string(v)); }
  Dump& nums(const char* tag, const std::vector<double>& v) {
    integer(tag, static_cast<long>(v.size()));
    for (double x : v) num(tag, x);
    return *this;
  }
  Dump& points(const char* tag, const std::map<std::string, Vec2>& pts) {
    integer(tag, static_cast<long>(pts.size()));
    for (const auto& [name, p] : pts) str(tag, name).vec(tag, p);
    return *this;
  }
  template <class T>
  Dump& count(const char* tag, const std::vector<T>& v) {
    return integer(tag, static_cast<long>(v.size()));
  }
  // The two attachments of a loop, spring or point force.
  Dump& ends(const std::string& a, const Vec2& pa, const std::string& b, const Vec2& pb) {
    return str("a", a).vec("pa", pa).str("b", b).vec("pb", pb);
  }
  // A drive load's rate gate and profile, each present or not.
  Dump& gate(const std::optional<RateGate>& g) {
    integer("gate", g ? 1 : 0);
    return g ? str("gate_joint", g->joint).integer("gate_sign", g->sign) : *this;
  }
  Dump& profile(const std::optional<LoadProfile>& p) {
    integer("profile", p ? 1 : 0);
    if (!p) return *this;
    return str("of", p->of)
        .num("a0", p->a0)
        .nums("a", p->a)
        .nums("b", p->b)
        .nums("theta", p->table_theta_rad)
        .nums("tau", p->table_value)
        .nums("d2", p->table_d2);
  }
  std::string text;

 private:
  Dump& put(const char* tag, const std::string& v) {
    text += std::string(tag) + "=" + v + "\n";
    return *this;
  }
};

std::string dump(const Scene& s) {
  Dump d;
  d.str("name", s.name).str("description", s.description);
  d.count("bodies", s.bodies);
  for (const auto& b : s.bodies)
    d.str("body", b.name)
        .num("mass", b.mass_kg)
        .vec("com", b.com_m)
        .num("inertia", b.inertia_kgm2)
        .points("pts", b.points);
  d.points("ground_points", s.ground_points);
  d.count("joints", s.joints);
  for (const auto& j : s.joints)
    d.str("joint", j.name)
        .integer("type", static_cast<long>(j.type))
        .str("parent", j.parent)
        .str("child", j.child)
        .vec("pp", j.parent_point)
        .vec("cp", j.child_point)
        .vec("axis", j.axis)
        .num("offset", j.offset_rad)
        .num("guess", j.guess);
  d.count("loops", s.loops);
  for (const auto& l : s.loops) {
    d.str("loop", l.name).ends(l.body_a, l.point_a, l.body_b, l.point_b).integer("branch", l.branch ? 1 : 0);
    if (l.branch) d.str("branch_joint", l.branch->joint).integer("sign", l.branch->sign);
  }
  d.count("gears", s.gears);
  for (const auto& g : s.gears)
    d.str("gear", g.name).str("driver", g.driver).str("driven", g.driven).num("ratio", g.ratio);
  d.str("independent", s.independent).integer("range", s.independent_range ? 1 : 0);
  if (s.independent_range)
    d.num("min", s.independent_range->min).num("max", s.independent_range->max);
  d.count("torques", s.joint_torques);
  for (const auto& t : s.joint_torques)
    d.str("torque", t.name).str("joint", t.joint).num("value", t.value).gate(t.active_when).profile(t.profile);
  d.count("resistances", s.resistances);
  for (const auto& r : s.resistances)
    d.str("resistance", r.name)
        .str("body", r.body)
        .integer("law", static_cast<long>(r.law))
        .num("c", r.coefficient);
  d.count("springs", s.springs);
  for (const auto& sp : s.springs)
    d.str("spring", sp.name)
        .ends(sp.body_a, sp.point_a, sp.body_b, sp.point_b)
        .num("k", sp.stiffness_N_per_m)
        .num("L0", sp.rest_length_m);
  d.count("point_forces", s.point_forces);
  for (const auto& pf : s.point_forces)
    d.str("point_force", pf.name)
        .ends(pf.body_a, pf.point_a, pf.body_b, pf.point_b)
        .num("value", pf.value)
        .gate(pf.active_when)
        .profile(pf.profile);
  d.integer("optimize", s.optimize ? 1 : 0);
  if (s.optimize) {
    const auto& o = *s.optimize;
    for (const auto& l : o.loads) d.str("design", l.load).str("same_as", l.same_as).num("shift", l.shift_rad);
    d.str("of", o.of)
        .str("force", o.force)
        .integer("harmonics", o.harmonics)
        .num("max_load", o.max_load)
        .integer("nonnegative", o.nonnegative ? 1 : 0)
        .str("objective", o.objective)
        .num("p", o.p);
  }
  d.count("motors", s.motors);
  for (const auto& m : s.motors)
    d.str("motor", m.name)
        .str("joint", m.joint)
        .num("stall", m.stall_torque)
        .num("w0", m.no_load_speed);
  d.integer("gravity", s.gravity.enabled ? 1 : 0).vec("g", s.gravity.g_m_s2);
  d.count("constraint_forces", s.outputs.constraint_forces);
  for (const auto& c : s.outputs.constraint_forces)
    d.str("cf", c.name).str("joint", c.joint).vec("dir", c.direction);
  for (const auto* list : {&s.outputs.bodies, &s.outputs.joints, &s.outputs.reactions}) {
    d.count("list", *list);
    for (const auto& n : *list) d.str("item", n);
  }
  d.integer("reactions_all", s.outputs.reactions_all ? 1 : 0);
  d.integer("shaking", s.outputs.shaking ? 1 : 0);
  d.num("q0", s.initial.q).num("qdot0", s.initial.qdot);
  d.num("duration", s.simulation.duration_s)
      .num("dt_out", s.simulation.output_interval_s)
      .num("tol", s.simulation.tolerance);
  const Validation& v = s.validation;
  d.num("v_duration", v.duration_s)
      .num("ref_tol", v.reference_tolerance)
      .str("ref_int", v.reference_integrator);
  d.count("thresholds", v.thresholds);
  for (const auto& t : v.thresholds)
    d.str("quantity", t.quantity)
        .num("grid", t.grid_deg)
        .str("interp", t.interpolation)
        .num("max", t.max_error);
  d.num("cadence", v.calibrate_cadence_Hz)
      .num("power", v.calibrate_power_W)
      .str("load", v.calibrate_load);
  d.str("note", v.note).integer("compare", static_cast<long>(v.compare.size()));
  for (const auto& c : v.compare)
    d.str("quantity", c.quantity)
        .num("value", c.value)
        .str("unit", c.unit)
        .str("source", c.source)
        .str("explanation", c.explanation);
  return d.text;
}

// Writes, reads back (as the same file, so source_file agrees) and checks both equalities.
void expect_round_trip(const Scene& s, const std::string& what) {
  const std::string yaml = scene_to_yaml(s);
  Scene back;
  try {
    back = parse_scene(yaml, s.source_file);
  } catch (const SceneError& e) {
    ADD_FAILURE() << what << ": the written scene does not load: " << e.what() << "\n" << yaml;
    return;
  }
  EXPECT_EQ(dump(back), dump(s)) << what << "\n" << yaml;
  EXPECT_EQ(scene_hash(back), scene_hash(s)) << what;
  EXPECT_EQ(back.source_file, s.source_file);
  // A fixed point: writing the scene read back gives the same text.
  EXPECT_EQ(scene_to_yaml(back), yaml) << what;
}

std::vector<std::string> shipped_scene_files() {
  std::vector<std::string> files;
  for (const char* dir : {"", "/hard"})
    for (const auto& e : std::filesystem::directory_iterator(std::string(RDYN_SCENES) + dir))
      if (e.path().extension() == ".yaml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

TEST(SceneWrite, EveryShippedSceneReadsBackEqual) {
  const auto files = shipped_scene_files();
  ASSERT_GE(files.size(),
            15u);  // 7 scenes and 8 hard ones at the time of writing
  for (const auto& f : files) expect_round_trip(load_scene(f), f);
}

TEST(SceneWrite, TestScenesReadBackEqual) {
  for (bool gravity : {false, true})
    expect_round_trip(parse_scene(test::parallelogram_yaml(1.25, gravity), "parallelogram.yaml"),
                      "parallelogram");
  // Every load kind on the four-bar: a gated table profile, a Fourier profile, a spring, a motor.
  const std::string loads =
      "  - {type: joint_torque, name: f, joint: crank, profile: {of: rocker, "
      "fourier: {a0: 2, a: [0.5], b: [0, -1]}}}\n"
      "  - {type: joint_torque, name: t, joint: crank, torque_Nm: -3, "
      "active_when: {joint: rocker, rate: negative},\n"
      "     profile: {of: crank, table_deg: [[-10, 1], [100.3, 4], [200.7, 2], "
      "[333.3, -1]]}}\n"
      "  - {type: spring, name: s, body_a: ground, point_a: [0.1, 0.2], "
      "body_b: rocker, point_b: C,"
      " stiffness_N_per_m: 150, rest_length_m: 0.3}\n"
      "  - {type: motor, name: m, joint: crank, stall_torque_Nm: 2.5, "
      "no_load_speed_rad_s: 30}\n";
  expect_round_trip(parse_scene(test::fourbar_with_loads(loads, "0.0031"), "fourbar-loads.yaml"),
                    "fourbar loads");
}

// A prismatic independent coordinate with a declared range, a gear, a prismatic motor and force,
// outputs `all`, a branch, thresholds, calibration and compared values.
const char* kSlider = R"(name: slider_gear
description: A slider-crank with a geared flywheel.
ground_points: {O: [0, 0], F: [0.2, 0.1]}
bodies:
  - {name: crank, mass_kg: 0.4, com_m: [0.01, 0], inertia_kgm2: 2.0e-4, points: {B: [0.05, 0]}}
  - {name: rod, mass_kg: 0.6, com_m: [0.08, 0], inertia_kgm2: 2.0e-3, points: {C: [0.2, 0]}}
  - {name: slider, mass_kg: 1.5, inertia_kgm2: 1.0e-3}
  - {name: flywheel, mass_kg: 2, inertia_kgm2: 0.01}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank, offset_deg: 17.3, guess_deg: 60}
  - {name: rod, type: revolute, parent: crank, parent_point: B, child: rod, guess_deg: -72}
  - {name: slider, type: prismatic, parent: ground, parent_point: O, child: slider, axis: [3, 0.001], guess_m: 0.21}
  - {name: fly, type: revolute, parent: ground, parent_point: F, child: flywheel}
loops:
  - {name: pin, body_a: rod, point_a: C, body_b: slider, point_b: [0, 0], branch: {joint: rod, sign: negative}}
gears:
  - {name: g, driver: crank, driven: fly, ratio: -2.5}
independent: slider
independent_range: [0.16, 0.24]
loads:
  - {type: motor, name: push, joint: slider, stall_force_N: 20, no_load_speed_m_s: 0.7}
  - {type: joint_torque, name: friction, joint: slider, force_N: -1.5, active_when: {joint: slider, rate: positive}}
  - {type: resistance, name: drag, body: flywheel, law: quadratic, coefficient: 1.0e-4}
gravity: {enabled: true, g_m_s2: [0.3, -9.80665]}
outputs:
  constraint_forces:
    - {name: rod_axial, joint: rod, direction: [0.6, 0.8]}
  bodies: [flywheel]
  joints: all
  reactions: all
  shaking: true
initial: {q: 0.2, qdot: -0.1}
simulation: {duration_s: 1.5, output_interval_s: 0.001, tolerance: 1.0e-10}
validation:
  duration_s: 0.75
  reference_tolerance: 1.0e-11
  reference_integrator: cpodes
  thresholds:
    - {quantity: qdot, grid_deg: 5, interpolation: akima, max_error: 1.0e-3}
    - {quantity: rod_axial, max_error: 2.0e-3}
  calibrate: {cadence_Hz: 0.5, load: push}
  compare:
    - {quantity: peak_force_N, value: 12.5, unit: N, source: a paper, explanation: none}
)";

TEST(SceneWrite, EveryKindOfFieldReadsBackEqual) {
  const Scene s = parse_scene(kSlider, "slider.yaml");
  ASSERT_EQ(s.outputs.joints.size(), 4u);
  ASSERT_EQ(s.outputs.reactions.size(), 5u);  // four joints, then the loop
  expect_round_trip(s, "slider");
  const std::string yaml = scene_to_yaml(s);
  // The expanded forms: `joints: all` as the list it stands for (`reactions: all` stays: it
  // also says how the reduced model treats reactions it cannot give), named points as
  // coordinates, radians.
  EXPECT_NE(yaml.find("joints: [crank, rod, slider, fly]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("reactions: all"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("parent_point: [0.2, 0.1]"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("force_N: -1.5"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("stall_force_N: 20, no_load_speed_m_s: 0.7"), std::string::npos) << yaml;
  auto count = [&](const std::string& key) {
    size_t n = 0;
    for (auto at = yaml.find(key); at != std::string::npos; at = yaml.find(key, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("_deg:"), count("grid_deg:")) << "angles are written in radians\n" << yaml;
  EXPECT_EQ(count("offset_rad:"), 3u);
}

TEST(SceneWrite, StartsWithACommentNamingTheScene) {
  const Scene s = parse_scene(kSlider, "dir/slider.yaml");
  const std::string yaml = scene_to_yaml(s);
  EXPECT_EQ(yaml.rfind("# Written by rdyn from scene 'slider_gear' (dir/slider.yaml).\n", 0), 0u)
      << yaml;
}

// The bicycle is made by its generator: the written scene has no generator block but the bodies and
// joints it made, and gives the same scene (hash included: the same table).
TEST(SceneWrite, GeneratedSceneIsWrittenExpanded) {
  const Scene s = load_scene("bicycle");
  const std::string yaml = scene_to_yaml(s);
  EXPECT_EQ(yaml.find("bicycle_leg"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("\nbodies:\n"), std::string::npos);
  EXPECT_EQ(yaml.find("dissipates"), std::string::npos)
      << "dissipates is written as its coefficient";
  expect_round_trip(s, "bicycle");
}

// Values no degree or named point can give, set in code: arbitrary radians (x·π/180 does not reach
// every double), unit vectors whose renormalisation would move them an ulp, −0, extremes of the
// limits, a table profile at arbitrary radian knots.
TEST(SceneWrite, ValuesSetInCodeReadBackBitForBit) {
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    Scene s = parse_scene(kSlider, "slider.yaml");
    for (auto& j : s.joints) {
      if (j.type == JointType::Revolute) {
        j.offset_rad = 3.0 * u(rng);
        j.guess = (trial == 0 ? -0.0 : 1e-7 * u(rng)) + (j.name == "rod" ? -1.25 : 1.0);
      } else {
        const Vec2 a{u(rng), u(rng)};
        const double len = std::hypot(a.x, a.y);
        j.axis = {a.x / len, a.y / len};
      }
    }
    const Vec2 d{u(rng), u(rng)};
    const double len = std::hypot(d.x, d.y);
    s.outputs.constraint_forces[0].direction = {d.x / len, d.y / len};
    s.bodies[0].mass_kg = 1e6 * std::abs(u(rng)) + 1e-6;
    s.bodies[1].com_m = {0.1 + 0.2, trial == 0 ? -0.0 : 1e-300 * u(rng)};
    s.initial.qdot = 1e4 * u(rng);
    std::vector<double> theta, value;
    for (int i = 0; i < 7; ++i) {
      theta.push_back(-1.0 + i * 0.8 + 0.01 * u(rng));
      value.push_back(u(rng));
    }
    s.joint_torques.push_back({"profiled", "crank", 0.3 * u(rng), std::nullopt,
                               make_table_profile("crank", theta, value)});
    ASSERT_NO_THROW(check_scene(s));
    expect_round_trip(s, fmt::format("trial {}", trial));
    if (HasFailure()) break;
  }
}

// Text the reader accepted reads back equal however it is written: YAML indicators, comment and
// mapping markers, leading and trailing spaces, quotes, backslashes, line breaks (including the
// Unicode ones YAML folds), control characters, non-ASCII text; and names that are YAML words for
// null and booleans.
TEST(SceneWrite, HostileTextReadsBackEqual) {
  const std::vector<std::string> texts = {
      "",
      "a: b # c",
      "#: not a comment",
      "  leading and trailing spaces  ",
      "line one\nline two\n\n  indented line\n",
      "quotes \" and ' and \\ backslash \\n not a newline",
      "- a list? [no] {no} & * ! | > % @ `",
      "tab\there, carriage\rreturn, bell\x07, escape\x1b, delete\x7f",
      "unicode: é ü ß 日本語 🚲 · N·m² — NEL\u0085 LS\u2028 PS\u2029 BOM\ufeff",
      "null",
      "~",
      "true",
      "no",
      "1.5",
      "0x10",
      ".inf",
      "'single'",
      "\"double\"",
      "---",
      "...",
      "? key",
      std::string(4000, 'x') + "\n#",
      // Not UTF-8 (the reader takes such bytes as they are): Latin-1, an overlong form, a
      // surrogate, a cut sequence before the closing quote, a lone continuation byte.
      "caf\xe9 \xff", "overlong \xc0\xaf", "surrogate \xed\xa0\x80", "cut \xe6\x97", "\x85 \xe2\x80",
  };
  Scene s = parse_scene(kSlider, "slider.yaml");
  for (const auto& t : texts) {
    s.description = t;
    s.validation.note = t + " (note)";
    s.validation.calibrate_load = t.empty() ? "a\"quoted\"load" : t;
    s.validation.compare[0].unit = t;
    s.validation.compare[0].source = "#: " + t;
    s.validation.compare[0].explanation = t + "\n";
    expect_round_trip(s, "text: " + t);
  }
  // The same text through a YAML file first: what the reader accepted is written back equal.
  const std::string yaml = std::string(kSlider) +
                           "description: |\n  Block text with \"quotes\", a "
                           "#: and\n   an indented line\n";
  std::string replaced = yaml;
  const std::string one_line = "description: A slider-crank with a geared flywheel.\n";
  replaced.replace(replaced.find(one_line), one_line.size(), "");
  expect_round_trip(parse_scene(replaced, "block.yaml"), "block scalar");
  std::string latin1 = kSlider;
  latin1.replace(latin1.find(one_line), one_line.size(), "description: caf\xe9 cr\xe8me\n");
  const Scene l = parse_scene(latin1, "latin1.yaml");
  ASSERT_EQ(l.description, "caf\xe9 cr\xe8me");
  expect_round_trip(l, "Latin-1 file");
}

TEST(SceneWrite, NamesThatAreYamlWordsAreQuoted) {
  std::string y = kSlider;
  auto swap = [&](const std::string& from, const std::string& to) {
    for (auto at = y.find(from); at != std::string::npos; at = y.find(from, at + to.size()))
      y.replace(at, from.size(), to);
  };
  swap("flywheel", "\"yes\"");
  swap("name: drag", "name: \"null\"");
  swap("B: [0.05, 0]", "\"on\": [0.05, 0]");
  swap("parent_point: B", "parent_point: \"on\"");
  swap("name: g,", "name: \"off\",");
  const Scene s = parse_scene(y, "words.yaml");
  ASSERT_EQ(s.bodies[3].name, "yes");
  ASSERT_EQ(s.resistances[0].name, "null");
  expect_round_trip(s, "yaml words");
}

TEST(SceneWrite, ValuesNoSceneFileCanHoldAreRefusedNamingTheField) {
  const Scene base = parse_scene(kSlider, "slider.yaml");
  struct Bad {
    std::function<void(Scene&)> apply;
    std::string field, message;
  };
  const std::vector<Bad> bad = {
      {[](Scene& s) { s.bodies[1].mass_kg = std::nan(""); }, "bodies.rod.mass_kg", "not finite"},
      {[](Scene& s) { s.gravity.g_m_s2.y = -INFINITY; }, "gravity.g_m_s2[1]", "not finite"},
      {[](Scene& s) { s.bodies[0].com_m.x = 1e-310; }, "bodies.crank.com_m[0]", "subnormal"},
  };
  for (const auto& b : bad) {
    Scene s = base;
    b.apply(s);
    try {
      scene_to_yaml(s);
      ADD_FAILURE() << b.field << " was written";
    } catch (const SceneError& e) {
      EXPECT_EQ(e.file(), "slider.yaml");
      EXPECT_EQ(e.field(), b.field) << e.what();
      EXPECT_NE(e.message().find(b.message), std::string::npos) << e.what();
    }
  }
}

// The dump above must see every field, or the round-trip tests could miss one: each mutation
// changes the dump, and the mutated scene still reads back equal (so the writer writes it).
TEST(SceneWrite, EveryFieldIsWrittenAndCompared) {
  const Scene base = parse_scene(kSlider, "slider.yaml");
  const std::vector<std::pair<const char*, std::function<void(Scene&)>>> mutations = {
      {"description", [](Scene& s) { s.description += "!"; }},
      {"body mass", [](Scene& s) { s.bodies[0].mass_kg *= 1 + 1e-15; }},
      {"body point", [](Scene& s) { s.bodies[0].points["B"].y = 1e-9; }},
      {"ground point",
       [](Scene& s) {
         s.ground_points["extra"] = {1, 2};
       }},
      {"joint offset",
       [](Scene& s) { s.joints[0].offset_rad = std::nextafter(s.joints[0].offset_rad, 1.0); }},
      {"joint guess", [](Scene& s) { s.joints[3].guess = 0.5; }},
      {"branch sign", [](Scene& s) { s.loops[0].branch->sign = +1; }},
      {"no branch", [](Scene& s) { s.loops[0].branch.reset(); }},
      {"gear ratio", [](Scene& s) { s.gears[0].ratio = 3; }},
      {"range", [](Scene& s) { s.independent_range->max = 0.23; }},
      {"torque value", [](Scene& s) { s.joint_torques[0].value = -1.25; }},
      {"gate sign", [](Scene& s) { s.joint_torques[0].active_when->sign = -1; }},
      {"law", [](Scene& s) { s.resistances[0].law = ResistanceLaw::Constant; }},
      {"coefficient", [](Scene& s) { s.resistances[0].coefficient = 2e-4; }},
      {"motor speed", [](Scene& s) { s.motors[0].no_load_speed = 0.8; }},
      {"gravity off", [](Scene& s) { s.gravity.enabled = false; }},
      {"outputs.bodies", [](Scene& s) { s.outputs.bodies.clear(); }},
      {"outputs.joints", [](Scene& s) { s.outputs.joints.pop_back(); }},
      {"outputs.reactions", [](Scene& s) { s.outputs.reactions = {"pin"}, s.outputs.reactions_all = false; }},
      {"reactions listed", [](Scene& s) { s.outputs.reactions_all = false; }},  // the same list, by name
      {"shaking", [](Scene& s) { s.outputs.shaking = false; }},
      {"qdot", [](Scene& s) { s.initial.qdot = 0.3; }},
      {"duration", [](Scene& s) { s.simulation.duration_s = 2; }},
      {"output interval", [](Scene& s) { s.simulation.output_interval_s = 0.002; }},
      {"tolerance", [](Scene& s) { s.simulation.tolerance = 1e-8; }},
      {"validation duration", [](Scene& s) { s.validation.duration_s = 0; }},
      {"reference tolerance", [](Scene& s) { s.validation.reference_tolerance = 1e-9; }},
      {"reference integrator", [](Scene& s) { s.validation.reference_integrator = "rk3"; }},
      {"threshold interpolation", [](Scene& s) { s.validation.thresholds[0].interpolation = ""; }},
      {"threshold grid", [](Scene& s) { s.validation.thresholds[1].grid_deg = 2; }},
      {"threshold error", [](Scene& s) { s.validation.thresholds[1].max_error = 0.01; }},
      {"calibrate power", [](Scene& s) { s.validation.calibrate_power_W = 40; }},
      {"calibrate load", [](Scene& s) { s.validation.calibrate_load = ""; }},
      {"calibrate cadence", [](Scene& s) { s.validation.calibrate_cadence_Hz = 0.75; }},
      {"note", [](Scene& s) { s.validation.note = "n"; }},
      {"compare value", [](Scene& s) { s.validation.compare[0].value = 13; }},
      {"compare unit", [](Scene& s) { s.validation.compare[0].unit = "kN"; }},
      {"compare source", [](Scene& s) { s.validation.compare[0].source = "b"; }},
      {"compare explanation", [](Scene& s) { s.validation.compare[0].explanation = "e"; }},
      {"fourier profile",
       [](Scene& s) {
         s.joint_torques[0].joint = "crank";
         s.joint_torques[0].active_when.reset();
         s.joint_torques[0].profile = LoadProfile{"crank", 0.5, {0.25}, {-0.125, 1e-3}, {}, {}, {}};
       }},
  };
  const std::string d0 = dump(base);
  for (const auto& [what, apply] : mutations) {
    Scene s = base;
    apply(s);
    ASSERT_NO_THROW(check_scene(s)) << what;
    EXPECT_NE(dump(s), d0) << what;
    expect_round_trip(s, what);
  }
}

// The checked writer returns the same text, and refuses a scene whose written form reads back as
// another scene (fields the format has no key for, set in code) or does not load.
TEST(SceneWrite, CheckedWriterRefusesWhatDoesNotReadBack) {
  const Scene s = parse_scene(kSlider, "slider.yaml");
  EXPECT_EQ(scene_to_yaml_checked(s), scene_to_yaml(s));
  Scene axis = s;
  axis.joints[0].axis = {0, 1};  // a revolute joint has no axis key
  EXPECT_THROW(scene_to_yaml_checked(axis), NumericalError);
  Scene offset = s;
  offset.joints[2].offset_rad = 0.5;  // nor a prismatic one an offset
  try {
    scene_to_yaml_checked(offset);
    ADD_FAILURE() << "written";
  } catch (const NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("scene hash"), std::string::npos) << e.what();
  }
  Scene invalid = s;
  invalid.bodies[0].mass_kg = -1;
  EXPECT_THROW(scene_to_yaml_checked(invalid), SceneError);
}

}  // namespace
}  // namespace rdyn::models
