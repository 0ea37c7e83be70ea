// Checked YAML reading (models/yaml_fields.cpp): unknown keys suggested with their line,
// overrides applied by path and item name, limits on hostile structures, a second document
// refused, numbers that underflow refused; the helpers on inputs with known answers.
#include "models/yaml_fields.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "scene_yaml_checks.hpp"

namespace rdyn::models {
namespace {

using namespace test;

// The helpers themselves, on inputs whose answers are known by hand.
TEST(YamlFields, EditDistanceCountsInsertionsDeletionsAndSubstitutions) {
  EXPECT_EQ(yaml::edit_distance("mass_kg", "mass_kg"), 0u);
  EXPECT_EQ(yaml::edit_distance("mas_kg", "mass_kg"), 1u);     // one insertion
  EXPECT_EQ(yaml::edit_distance("masss_kg", "mass_kg"), 1u);   // one deletion
  EXPECT_EQ(yaml::edit_distance("mass_kx", "mass_kg"), 1u);    // one substitution
  EXPECT_EQ(yaml::edit_distance("", "abc"), 3u);
  EXPECT_EQ(yaml::edit_distance("kitten", "sitting"), 3u);     // the textbook pair
}

TEST(YamlFields, KeyPathsAndIndicesAreSplitAndBounded) {
  EXPECT_EQ(yaml::split_key_path("loads.brake.coefficient"),
            (std::vector<std::string>{"loads", "brake", "coefficient"}));
  EXPECT_EQ(yaml::split_key_path("a..b"), (std::vector<std::string>{"a", "", "b"}));  // the empty part is refused later
  size_t i = 99;
  EXPECT_TRUE(yaml::parse_index("2", 3, i));
  EXPECT_EQ(i, 2u);
  EXPECT_FALSE(yaml::parse_index("3", 3, i));   // past the end
  EXPECT_FALSE(yaml::parse_index("-1", 3, i));  // digits only
  EXPECT_FALSE(yaml::parse_index("1e0", 3, i));
  EXPECT_FALSE(yaml::parse_index("1234567890", 20000000000ull, i));  // more than 9 digits
}

TEST(YamlFields, LocateFieldFindsItemsByIndexOrNameAndStopsAtTheDeepestAncestor) {
  const YAML::Node root = yaml::load_checked_yaml(kFourbar, "test.yaml");
  EXPECT_EQ(yaml::line_of(yaml::locate_field(root, "bodies[1].mass_kg")), line_in(kFourbar, "name: coupler"));
  EXPECT_EQ(yaml::line_of(yaml::locate_field(root, "joints.rocker.guess_deg")), line_in(kFourbar, "name: rocker, type"));
  // A field that is not written (derived or defaulted): its nearest written ancestor.
  EXPECT_EQ(yaml::line_of(yaml::locate_field(root, "loops.C.branch")), line_in(kFourbar, "name: C,"));
  EXPECT_EQ(yaml::line_of(yaml::locate_field(root, "independent")), line_in(kFourbar, "independent: crank"));
}

TEST(YamlFields, UnitVectorsAlreadyNormalisedAreKeptBitForBit) {
  const Vec2 v{0.6, 0.8};
  const Vec2 u = yaml::unit_vector(v, std::hypot(v.x, v.y));
  EXPECT_EQ(u.x, v.x);
  EXPECT_EQ(u.y, v.y);
  const Vec2 w = yaml::unit_vector({3, 4}, 5);
  EXPECT_DOUBLE_EQ(w.x, 0.6);
  EXPECT_DOUBLE_EQ(w.y, 0.8);
}

TEST(YamlFields, UnknownKeySuggestsNearestAndNamesLine) {
  std::string y = kFourbar;
  y.replace(y.find("mass_kg: 0.9"), 12, "mas_kg: 0.9");
  const std::string e = error_of(y);
  EXPECT_NE(e.find("test.yaml:7"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'mass_kg'"), std::string::npos) << e;
}

TEST(YamlFields, OverridesReachScalarsByPathAndName) {
  const Scene s = parse_scene(
      kFourbar, "t.yaml",
      {parse_override("loads.bearing.coefficient=0.25"), parse_override("bodies.1.mass_kg=2.5")});
  EXPECT_DOUBLE_EQ(s.resistances[0].coefficient, 0.25);
  EXPECT_DOUBLE_EQ(s.bodies[1].mass_kg, 2.5);
  const Scene b = load_scene("bicycle", {parse_override("bicycle_leg.hip_torque_Nm=50")});
  EXPECT_DOUBLE_EQ(b.joint_torques[0].value, 50.0);
  EXPECT_NE(error_of(kFourbar, {parse_override("loads.nosuch.coefficient=1")}).find("no list item"),
            std::string::npos);
  EXPECT_THROW(parse_override("novalue"), SceneError);
  // The same angle in another unit is replaced, not refused as "q or q_deg, not both" (the
  // crane gives initial.q in radians).
  const Scene c = load_scene("crane-luffing", {parse_override("initial.q_deg=75")});
  EXPECT_NEAR(c.initial.q, 75 * M_PI / 180, 1e-15);
  const Scene back = load_scene("crane-luffing", {parse_override("initial.q_deg=75"), parse_override("initial.q=1.5")});
  EXPECT_DOUBLE_EQ(back.initial.q, 1.5);
  // A list as a flow list: a scene without a range is given one (`independent_range.0=…` had no
  // item to set), and the other unit's key is replaced as for scalars.
  const Scene r = parse_scene(kFourbar, "t.yaml", {parse_override("independent_range_deg=[-10, 80]")});
  ASSERT_TRUE(r.independent_range);
  EXPECT_NEAR(r.independent_range->min, -10 * M_PI / 180, 1e-15);
  EXPECT_NEAR(r.independent_range->max, 80 * M_PI / 180, 1e-15);
  const Scene r2 = parse_scene(kFourbar, "t.yaml",
                               {parse_override("independent_range_deg=[-10, 80]"),
                                parse_override("independent_range=[-0.2, 1.0]")});
  ASSERT_TRUE(r2.independent_range);
  EXPECT_DOUBLE_EQ(r2.independent_range->max, 1.0);
  // `all` replaced by a list (outputs take either); another scalar keeps `[…]` as its text.
  const Scene all = parse_scene(kFourbar + std::string("outputs: {reactions: all}\n"), "t.yaml",
                                {parse_override("outputs.reactions=[crank, C]")});
  EXPECT_EQ(all.outputs.reactions, (std::vector<std::string>{"crank", "C"}));
  EXPECT_EQ(parse_scene(kFourbar + std::string("description: old\n"), "t.yaml", {parse_override("description=[draft]")})
                .description,
            "[draft]");
}

TEST(YamlFields, MalformedEmptyAndBinaryInputsAreRefused) {
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  EXPECT_NE(error_of("name: [unclosed\n").find("test.yaml"), std::string::npos);
  EXPECT_NE(error_of(std::string("\x01\x02\0\x7f", 4)).find("NUL"), std::string::npos);
  EXPECT_NE(error_of("just a string").find("mapping"), std::string::npos);
  EXPECT_NE(error_of(std::string(kFourbar).substr(0, 200)).find("test.yaml"), std::string::npos);
}

TEST(YamlFields, ASecondDocumentIsRefusedAtItsMarker) {
  // yaml-cpp's Load reads the first document only: what follows `---` was silently dropped.
  const std::string fb = kFourbar;
  const int marker_line = static_cast<int>(std::count(fb.begin(), fb.end(), '\n')) + 1;
  for (const std::string second : {"---\nname: other\n", "---\n", "...\n---\ngravity: {enabled: false}\n"}) {
    const SceneError e = refusal(fb + second);
    EXPECT_EQ(e.file(), "test.yaml");
    EXPECT_EQ(e.line(), marker_line + (second.rfind("...", 0) == 0 ? 1 : 0)) << second;
    EXPECT_NE(e.message().find("second YAML document"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(parse_scene("---\n" + fb, "test.yaml"));  // one document with its marker
  EXPECT_NO_THROW(parse_scene(fb + "...\n", "test.yaml"));   // one document with its end
}

TEST(YamlFields, DuplicateKeysAreRefusedWithTheirLineAndPath) {
  const std::string fb = kFourbar;
  struct Case {
    std::string yaml, field, second;  // scene, key path, text on the line of the repeated key
  };
  const std::string bike =
      "name: b\nbicycle_leg:\n  legs: 2\n  flywheel: {gear_ratio: 3, gear_ratio: 2}\n";
  const Case cases[] = {
      {fb + "name: again\n", "name", "name: again"},
      {with(fb, "mass_kg: 0.9,", "mass_kg: 0.9, mass_kg: 2,"), "bodies[2].mass_kg", "mass_kg: 2"},
      {with(fb, "points: {C: [0.2, 0]}", "points: {C: [0.2, 0], C: [0.3, 0]}"),
       "bodies[2].points.C", "C: [0.3"},
      {with(fb, "D: [0.3, 0]}", "D: [0.3, 0], A: [1, 1]}"), "ground_points.A", "A: [1, 1]"},
      {with(fb, "coefficient: 1.0e-3}", "coefficient: 1.0e-3, law: quadratic}"), "loads[0].law",
       "law: quadratic"},
      {fb + "validation:\n  duration_s: 1\n  note: x\n  duration_s: 2\n", "validation.duration_s",
       "duration_s: 2"},
      {bike, "bicycle_leg.flywheel.gear_ratio", "gear_ratio: 2"},
  };
  for (const auto& c : cases) expect_refused(c.yaml, c.field, "duplicate key", c.second);
}

TEST(YamlFields, MalformedOverridesAreRefusedNamingThem) {
  for (const char* bad : {"novalue", "=3", "a..b=1", ".a=1", "a.=1"}) {
    try {
      parse_override(bad);
      ADD_FAILURE() << bad;
    } catch (const SceneError& e) {
      EXPECT_EQ(e.field().rfind("--set " + std::string(bad).substr(0, 3), 0), 0u) << e.what();
    }
  }
  EXPECT_THROW(parse_override("k=" + std::string(5000, 'x')), SceneError);
  struct Case {
    std::string override_text, field, says;
  };
  const Case cases[] = {
      {"bodies.0.mas_kg=3", "--set bodies.0.mas_kg", "did you mean 'mass_kg'"},  // unknown key
      {"nosuch=3", "--set nosuch", "unknown key"},  // unknown top-level key
      {"bodies.1.mass_kg=heavy", "--set bodies.1.mass_kg", "expected a number"},  // not a number
      {"bodies.7.mass_kg=1", "--set bodies.7.mass_kg", "no list item '7'"},  // index out of range
      {"bodies.rocker.points.C.2=1", "--set bodies.rocker.points.C.2", "no scalar list item"},
      {"bodies.rocker.mass_kg=-1", "--set bodies.rocker.mass_kg",
       "must be in [1e-06"},  // out of range
      {"loads.bearing.coefficient=.nan", "--set loads.bearing.coefficient", "finite"},
      {"name=a b", "--set name", "not a valid name"},
      {"bodies=3", "--set bodies", "only scalar values"},
      {"bodies=[a, {b: 1}]", "--set bodies", "at most 64 scalar items"},  // no structure through --set
      {"ground_points=[1, 2]", "--set ground_points", "only scalars and lists"},
      {"independent_range=[1, [2]]", "--set independent_range", "scalar items"},
      {"independent_range_deg=[95, .nan]", "--set independent_range_deg", "independent_range_deg"},
      {"independent.x=3", "--set independent.x", "not a mapping"},
  };
  for (const auto& c : cases) expect_refused(kFourbar, c.field, c.says, "", {parse_override(c.override_text)});
}

TEST(YamlFields, HostileStructuresAreRefusedQuickly) {
  std::string laughs =
      "name: x\na0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";  // 10^30 nodes when expanded
  for (int i = 1; i < 30; ++i) {
    laughs += fmt::format("a{}: &a{} [", i, i);
    for (int k = 0; k < 10; ++k) laughs += fmt::format("{}*a{}", k ? ", " : "", i - 1);
    laughs += "]\n";
  }
  std::string many = "name: many\nbodies:\n";
  for (int i = 0; i < 1001; ++i)
    many += fmt::format("  - {{name: b{}, mass_kg: 1, inertia_kgm2: 1}}\n", i);
  std::string block_nest = "name: x\nbodies: ";
  for (int i = 0; i < 5000; ++i) block_nest += "- ";
  block_nest += "x\n";
  struct Case {
    std::string what, yaml, says;
  };
  const Case cases[] = {
      {"billion laughs", laughs, "more than 200000 nodes"},
      {"alias cycle", "name: x\nbodies: &a [*a]\n", "refers to its own ancestor"},
      {"1001 bodies", many, "at most 1000"},
      {"long string", "name: x\ndescription: " + std::string(5000, 'x') + "\n", "at most 4096"},
      {"long name", "name: " + std::string(65, 'x') + "\n", "not a valid name"},
      {"deep flow", "name: x\nbodies: " + std::string(100, '[') + std::string(100, ']') + "\n",
       "nested too deeply"},
      {"deep block", block_nest, "test.yaml"},
      {"complex key", "name: x\n? [a, b]\n: 1\n", "plain text"},
  };
  for (const auto& c : cases) {
    const auto start = std::chrono::steady_clock::now();
    const SceneError e = refusal(c.yaml);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_NE(std::string(e.what()).find(c.says), std::string::npos) << c.what << ": " << e.what();
    EXPECT_LT(seconds, 2.0) << c.what;  // a walk over 10^30 nodes would never return
  }
}

// Issue #9 leftovers: a body list item that is not a name, a load type that is not a word,
// and a nonzero number too small for a double all name their field (yaml-cpp alone said
// "bad conversion", and 1e-400 was read as 0).
TEST(YamlFields, MalformedItemsAndUnderflowingNumbersNameTheField) {
  const std::string fb = kFourbar;
  std::string y = fb + "outputs: {bodies: [crank, {a: 1}]}\n";
  EXPECT_EQ(refusal(y).field(), "outputs.bodies[1]");
  EXPECT_EQ(refusal(y).line(), line_in(y, "outputs:"));
  y = with(fb, "{type: resistance,", "{type: [resistance],");
  EXPECT_EQ(refusal(y).field(), "loads[0].type");
  y = fb + "gravity: {enabled: true, g_m_s2: [0, 1e-400]}\n";
  EXPECT_EQ(refusal(y).field(), "gravity.g_m_s2[1]");
  EXPECT_NE(std::string(refusal(y).what()).find("'1e-400' is too small"), std::string::npos) << refusal(y).what();
  y = fb + "gravity: {enabled: true, g_m_s2: [0, -2.5e-320]}\n";  // a denormal: digits lost
  EXPECT_EQ(refusal(y).field(), "gravity.g_m_s2[1]");
  // Zero written small is still zero; ordinary small numbers are fine.
  EXPECT_EQ(parse_scene(fb + "gravity: {enabled: true, g_m_s2: [0.0e-400, -1e-300]}\n", "t.yaml").gravity.g_m_s2.x, 0.0);
  // Through --set too.
  EXPECT_EQ(refusal(fb, {parse_override("initial.qdot=3e-400")}).field(), "--set initial.qdot");
}

// clone_with_marks: a copy whose every node (keys too) has the original's line and column,
// independent of the original, with aliased nodes still shared. YAML::Clone, the route it
// builds on, puts every node at the text's start (line 1): the test would fail on it.
void expect_same_marks(const YAML::Node& a, const YAML::Node& b, int& nodes) {
  ++nodes;
  EXPECT_EQ(a.Mark().line, b.Mark().line);
  EXPECT_EQ(a.Mark().column, b.Mark().column);
  EXPECT_EQ(a.Mark().pos, b.Mark().pos);
  ASSERT_EQ(a.Type(), b.Type());
  if (a.IsScalar()) {
    EXPECT_EQ(a.Scalar(), b.Scalar());
  }
  if (a.IsSequence()) {
    for (size_t i = 0; i < a.size(); ++i) expect_same_marks(a[i], b[i], nodes);
  }
  if (a.IsMap()) {
    auto j = b.begin();
    for (auto i = a.begin(); i != a.end(); ++i, ++j) {
      expect_same_marks(i->first, j->first, nodes);
      expect_same_marks(i->second, j->second, nodes);
    }
  }
}

TEST(YamlFields, CloneWithMarksKeepsEveryLineAndSharesAliases) {
  const std::string text = "name: x\nlist:\n  - {a: 1, b: [2, 3]}\n  - &k\n    c: 4\nother: *k\nlast: 5\n";
  const YAML::Node root = yaml::load_checked_yaml(text, "t.yaml");
  YAML::Node copy = yaml::clone_with_marks(root);
  int nodes = 0;
  expect_same_marks(root, copy, nodes);
  EXPECT_EQ(nodes, 21);  // the alias's mapping walked twice, through both names
  EXPECT_EQ(yaml::line_of(copy["last"]), 7);
  EXPECT_EQ(yaml::line_of(copy["list"][1]["c"]), 5);
  EXPECT_EQ(yaml::line_of(YAML::Clone(root)["last"]), 1);  // why the marks are copied: Clone's are all line 1
  // The alias is one node in the copy as in the original; the copy is not the original.
  EXPECT_TRUE(copy["other"].is(copy["list"][1]));
  copy["list"][1]["c"] = "9";
  EXPECT_EQ(copy["other"]["c"].Scalar(), "9");
  EXPECT_EQ(root["list"][1]["c"].Scalar(), "4");
  EXPECT_EQ(root["other"]["c"].Scalar(), "4");
}

}  // namespace
}  // namespace rdyn::models
