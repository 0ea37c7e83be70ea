// Scene reading: shipped scenes load; bad input gives SceneError naming file, line, field.
#include "models/scene_yaml.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "models/scene_hash.hpp"
#include "models/yaml_fields.hpp"
#include "scene_yaml_checks.hpp"

namespace rdyn::models {
namespace {

using namespace test;

TEST(SceneYaml, ShippedScenesLoad) {
  for (const char* name : {"bicycle", "fourbar", "slider-crank"}) {
    const Scene s = load_scene(name);
    EXPECT_EQ(s.name, name);
    EXPECT_FALSE(s.outputs.constraint_forces.empty()) << name;
  }
}

TEST(SceneYaml, BicycleResistanceDissipatesRequestedPower) {
  // Viscous: P = c ω² at the flywheel speed ω = gear_ratio · 2π · cadence.
  const Scene s = load_scene("bicycle");
  ASSERT_EQ(s.resistances.size(), 1u);
  const double omega = 3.0 * 2.0 * kPi * 1.0;
  EXPECT_NEAR(s.resistances[0].coefficient * omega * omega, 125.0, 1e-9);
  EXPECT_EQ(s.joint_torques.size(), 2u);  // two legs
  EXPECT_DOUBLE_EQ(s.joint_torques[0].value, 69.7);
}

TEST(SceneYaml, DissipatesOnAGearedBodyUsesTheRatio) {
  std::string y = kFourbar;
  y.replace(y.find("coefficient: 1.0e-3"), 19, "dissipates: {power_W: 10, cadence_Hz: 2}");
  const Scene s = parse_scene(y, "t.yaml");
  const double omega = 2.0 * 2.0 * kPi;  // crank is the independent joint's child
  EXPECT_NEAR(s.resistances[0].coefficient * omega * omega, 10.0, 1e-12);
}

TEST(SceneYaml, BadValuesAreRefusedWithTheirField) {
  std::string y = kFourbar;
  y.replace(y.find("mass_kg: 0.9"), 12, "mass_kg: 0.0");
  // check_scene names the item by name; the reader finds its line (the rocker is on line 7).
  EXPECT_NE(error_of(y).find("test.yaml:7: field 'bodies.rocker.mass_kg'"), std::string::npos)
      << error_of(y);
  y = kFourbar;
  y.replace(y.find("mass_kg: 0.9"), 12, "mass_kg: .nan");
  EXPECT_NE(error_of(y).find("finite"), std::string::npos) << error_of(y);
  y = kFourbar;
  y.replace(y.find("mass_kg: 0.9"), 12, "mass_kg: heavy");
  EXPECT_NE(error_of(y).find("expected a number, got 'heavy'"), std::string::npos) << error_of(y);
  y = kFourbar;
  y.replace(y.find("inertia_kgm2: 3.0e-3"), 20, "inertia_kgm2: -1");
  EXPECT_NE(error_of(y).find("inertia"), std::string::npos) << error_of(y);
}

TEST(SceneYaml, MechanismMustHaveOneDegreeOfFreedom) {
  std::string y = kFourbar;
  y.erase(y.find("loops:"), y.find("independent:") - y.find("loops:"));
  EXPECT_NE(error_of(y).find("3 degrees of freedom"), std::string::npos) << error_of(y);
}

TEST(SceneYaml, MissingSceneFileIsNamed) {
  try {
    load_scene("/nonexistent/scene.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml"), std::string::npos);
  }
}

TEST(SceneYaml, EveryShippedSceneAndTheGeneratorPassTheChecks) {
  // Names, ranges and duplicate keys are checked: every scene shipped must still load.
  int n = 0;
  for (const char* dir : {RDYN_SCENES, RDYN_SCENES "/hard", RDYN_SCENES "/chains"})
    for (const auto& f : std::filesystem::directory_iterator(dir))
      if (f.path().extension() == ".yaml") {
        EXPECT_NO_THROW(load_scene(f.path().string())) << f.path();
        ++n;
      }
  // 8 scenes (bicycle-profile and bicycle-muscle included) + 10 hard ones (chain-1 and chain-3
  // among them) + 4 chains.
  EXPECT_EQ(n, 22);
}

TEST(SceneYaml, NamesWithUnsafeCharactersAreRefusedWithTheirField) {
  const std::string fb =
      std::string(kFourbar) +
      "outputs:\n  constraint_forces:\n    - {name: axial, joint: rocker, direction: C}\n";
  // YAML spellings of a space, comma, quote, apostrophe, newline, slash, angle bracket, dot.
  for (const std::string bad :
       {"'a b'", "'a,b'", "'a\"b'", "\"a'b\"", "\"a\\nb\"", "a/b", "'<b>'", "a.b", "1a"}) {
    struct Case {
      std::string from, to, field;
    };
    const Case cases[] = {
        {"name: fb", "name: " + bad, "name"},
        {"name: coupler,", "name: " + bad + ",", "bodies[1].name"},
        {"{name: rocker, type", "{name: " + bad + ", type", "joints[2].name"},
        {"{name: C,", "{name: " + bad + ",", "loops[0].name"},
        {"name: bearing", "name: " + bad, "loads[0].name"},
        {"name: axial", "name: " + bad, "outputs.constraint_forces[0].name"},
    };
    for (const auto& c : cases) expect_refused(with(fb, c.from, c.to), c.field, "is not a valid name", c.to);
  }
  // Point names too (they are map keys).
  const std::string y = with(fb, "points: {B: [0.08, 0]}", "points: {B: [0.08, 0], 'a b': [0, 0]}");
  EXPECT_EQ(refusal(y).field(), "bodies.crank.points");
  EXPECT_EQ(refusal(y).line(), line_in(y, "'a b'"));
}

TEST(SceneYaml, DuplicateNamesWithinAKindAreRefused) {
  const std::string fb = kFourbar;
  std::string y =
      with(fb, "independent:",
           "  - {name: C, body_a: coupler, point_a: C, body_b: crank, point_b: B}\nindependent:");
  EXPECT_EQ(refusal(y).field(), "loops[1].name");
  EXPECT_EQ(refusal(y).line(), line_in(y, "body_b: crank"));
  y = with(fb, "{name: coupler, type", "{name: crank, type");
  EXPECT_EQ(refusal(y).field(), "joints[1].name");
  EXPECT_EQ(refusal(y).line(), line_in(y, "{name: crank, type: revolute, parent: crank"));
  y = fb + "  - {type: joint_torque, name: bearing, joint: crank, torque_Nm: 1}\n";
  EXPECT_EQ(refusal(y).field(), "loads[1].name");
}

TEST(SceneYaml, NumbersOutsideTheirRangesNameFieldAndLine) {
  const std::string fb = std::string(kFourbar) + "gravity: {enabled: true}\n";
  struct Case {
    std::string from, to, field;
  };
  const Case cases[] = {
      {"mass_kg: 0.9", "mass_kg: 1.0e308", "bodies.rocker.mass_kg"},
      {"inertia_kgm2: 3.0e-3", "inertia_kgm2: 1.0e7", "bodies.rocker.inertia_kgm2"},
      {"C: [0.2, 0]", "C: [0.2, -1.0e4]", "bodies.rocker.points.C[1]"},
      {"D: [0.3, 0]", "D: [1.0e300, 0]", "ground_points.D[0]"},
      {"guess_deg: 90", "guess_deg: 1.0e300", "joints[2].guess_deg"},
      {"coefficient: 1.0e-3", "coefficient: 1.0e9", "loads.bearing.coefficient"},
      {"coefficient: 1.0e-3", "coefficient: -1", "loads.bearing.coefficient"},
      {"coefficient: 1.0e-3", "dissipates: {power_W: -5, cadence_Hz: 1}",
       "loads[0].dissipates.power_W"},
      {"coefficient: 1.0e-3", "dissipates: {power_W: 5, cadence_Hz: 0}",
       "loads[0].dissipates.cadence_Hz"},
      {"gravity: {enabled: true}", "gravity: {g_m_s2: [0, -1.0e308]}", "gravity.g_m_s2[1]"},
      {"gravity: {enabled: true}", "initial: {q_deg: 1.0e300}", "initial.q_deg"},
      {"gravity: {enabled: true}", "initial: {cadence_Hz: -1.0e4}", "initial.cadence_Hz"},
      {"gravity: {enabled: true}", "initial: {qdot: 1.0e5}", "initial.qdot"},
      {"gravity: {enabled: true}", "simulation: {duration_s: 0}", "simulation.duration_s"},
      {"gravity: {enabled: true}", "simulation: {duration_s: 1.0e6}", "simulation.duration_s"},
      {"gravity: {enabled: true}", "simulation: {output_interval_s: 1.0e-9}",
       "simulation.output_interval_s"},
      {"gravity: {enabled: true}", "simulation: {duration_s: 1.0e4, output_interval_s: 1.0e-4}",
       "simulation.output_interval_s"},  // 1e8 rows
      {"gravity: {enabled: true}", "simulation: {tolerance: 1}", "simulation.tolerance"},
      {"gravity: {enabled: true}",
       "validation: {thresholds: [{quantity: qdot, grid_deg: 7, max_error: 0.01}]}",
       "validation.thresholds[0].grid_deg"},
      {"gravity: {enabled: true}",
       "validation: {thresholds: [{quantity: qdot, grid_deg: 10, max_error: 2}]}",
       "validation.thresholds[0].max_error"},
      {"gravity: {enabled: true}", "validation: {calibrate: {cadence_Hz: 50, power_W: 10}}",
       "validation.calibrate.cadence_Hz"},
      {"gravity: {enabled: true}", "validation: {calibrate: {cadence_Hz: 1, power_W: 1.0e6}}",
       "validation.calibrate.power_W"},
      // A given power of 0 would silently mean mean-speed mode: leave the key out for that.
      {"gravity: {enabled: true}", "validation: {calibrate: {cadence_Hz: 1, power_W: 0}}",
       "validation.calibrate.power_W"},
      {"gravity: {enabled: true}", "validation: {reference_tolerance: 0.1}",
       "validation.reference_tolerance"},
  };
  for (const auto& c : cases) expect_refused(with(fb, c.from, c.to), c.field, "", c.to);
}

TEST(SceneYaml, AGearCouplingAJointToItselfIsRefused) {
  // Two free wheels: joints (2) − gears (1) counted one degree of freedom, and ran with two.
  const std::string y = R"(name: wheels
ground_points: {A: [0, 0], B: [0.3, 0]}
bodies:
  - {name: wheel, mass_kg: 2, inertia_kgm2: 0.04}
  - {name: pinion, mass_kg: 0.5, inertia_kgm2: 1.0e-3}
joints:
  - {name: wheel, type: revolute, parent: ground, parent_point: A, child: wheel}
  - {name: pinion, type: revolute, parent: ground, parent_point: B, child: pinion}
gears:
  - {name: mesh, driver: wheel, driven: wheel, ratio: 2}
independent: wheel
)";
  const SceneError e = refusal(y);
  EXPECT_EQ(e.field(), "gears.mesh.driven");
  EXPECT_EQ(e.line(), line_in(y, "driven: wheel"));
  const std::string ok = with(y, "driven: wheel", "driven: pinion");
  EXPECT_NO_THROW(parse_scene(ok, "t.yaml"));
  EXPECT_EQ(refusal(with(ok, "ratio: 2", "ratio: 0")).field(), "gears.mesh.ratio");
  EXPECT_EQ(refusal(with(ok, "ratio: 2", "ratio: 2.0e3")).field(), "gears.mesh.ratio");
}

TEST(SceneYaml, DissipatesThroughAGearFromAnUnknownJointIsRefused) {
  // Crashed (null joint) before check_scene could refuse the unknown names.
  const std::string y = R"(name: g
bodies:
  - {name: wheel, mass_kg: 2, inertia_kgm2: 0.04}
joints:
  - {name: wheel, type: revolute, parent: ground, child: wheel}
gears:
  - {name: mesh, driver: nosuch, driven: wheel, ratio: 2}
independent: nosuch
loads:
  - {type: resistance, name: brake, body: wheel, law: viscous, dissipates: {power_W: 10, cadence_Hz: 1}}
)";
  EXPECT_EQ(refusal(y).field(), "loads.brake.dissipates");
}

TEST(SceneYaml, AValueKeyInTheOtherJointsUnitIsRefusedNamingTheRightKey) {
  // torque_Nm and force_N (stall_torque_Nm and stall_force_N, …) fill the same value: the
  // wrong one was read in the joint's own unit without a word (issue #23).
  const std::string sc = read_scene_text("slider-crank");
  struct Case {
    std::string from, to, field, right;
  };
  const Case cases[] = {
      {"joint: slider, force_N: -40.0", "joint: slider, torque_Nm: -40.0", "loads[1].torque_Nm", "give force_N"},
      {"stall_torque_Nm: 6.0, no_load_speed_rad_s: 60.0", "stall_force_N: 6.0, no_load_speed_rad_s: 60.0",
       "loads[0].stall_force_N", "give stall_torque_Nm"},
      {"stall_torque_Nm: 6.0, no_load_speed_rad_s: 60.0", "stall_torque_Nm: 6.0, no_load_speed_m_s: 60.0",
       "loads[0].no_load_speed_m_s", "give no_load_speed_rad_s"},
  };
  for (const auto& c : cases) {
    const std::string y = with(sc, c.from, c.to);
    const SceneError e = refusal(y);
    EXPECT_EQ(e.field(), c.field) << e.what();
    EXPECT_EQ(e.line(), line_in(y, c.to)) << e.what();
    EXPECT_NE(e.message().find(c.right), std::string::npos) << e.what();
  }
  // A force on a revolute joint's torque load; a motor on the slider with torque keys.
  const std::string fb = kFourbar;
  const std::string revolute_force = fb + "  - {type: joint_torque, name: d, joint: crank, force_N: 2}\n";
  expect_refused(revolute_force, "loads[1].force_N", "joint 'crank' is revolute (torques in N·m, speeds in rad/s): "
                 "give torque_Nm instead of force_N", "name: d");
  const std::string slider_motor =
      with(sc, "joint: crank, stall_torque_Nm: 6.0", "joint: slider, stall_torque_Nm: 6.0");
  const SceneError e = refusal(slider_motor);
  EXPECT_EQ(e.field(), "loads[0].stall_torque_Nm") << e.what();
  EXPECT_NE(e.message().find("joint 'slider' is prismatic (forces in N, speeds in m/s): give stall_force_N instead "
                             "of stall_torque_Nm"),
            std::string::npos)
      << e.what();
  // The right keys load; so does the slider's motor in its own units.
  EXPECT_NO_THROW(parse_scene(sc, "t.yaml"));
  EXPECT_NO_THROW(parse_scene(with(slider_motor, "stall_torque_Nm: 6.0, no_load_speed_rad_s: 60.0",
                                   "stall_force_N: 6.0, no_load_speed_m_s: 0.5"),
                              "t.yaml"));
}

TEST(SceneYaml, AMotorRunningAwayIsRefused) {
  const std::string y = with(read_scene_text("slider-crank"), "no_load_speed_rad_s: 60.0",
                             "no_load_speed_rad_s: -60.0");
  const SceneError e = refusal(y);
  EXPECT_EQ(e.field(), "loads.motor.no_load_speed_rad_s");
  EXPECT_EQ(e.line(), line_in(y, "no_load_speed_rad_s: -60.0"));
  EXPECT_NE(std::string(e.what()).find("opposite sign"), std::string::npos);
  // Both negative: a motor driving the other way is meant.
  EXPECT_NO_THROW(parse_scene(with(y, "stall_torque_Nm: 6.0", "stall_torque_Nm: -6.0"), "t.yaml"));
}


TEST(SceneYaml, LoopBranchNamesAJointAndASign) {
  const auto scene = load_scene("fourbar", {{"loops.C.branch.joint", "rocker"}, {"loops.C.branch.sign", "-1"}});
  ASSERT_TRUE(scene.loops[0].branch.has_value());
  EXPECT_EQ(scene.loops[0].branch->joint, "rocker");
  EXPECT_EQ(scene.loops[0].branch->sign, -1);
  EXPECT_FALSE(load_scene("fourbar").loops[0].branch.has_value());
  auto msg = [](std::vector<Override> o) {
    try {
      load_scene("fourbar", o);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const auto unknown = msg({{"loops.C.branch.joint", "rockr"}, {"loops.C.branch.sign", "positive"}});
  EXPECT_NE(unknown.find("unknown joint 'rockr'"), std::string::npos) << unknown;
  const auto sign = msg({{"loops.C.branch.joint", "rocker"}, {"loops.C.branch.sign", "up"}});
  EXPECT_NE(sign.find("expected positive or negative"), std::string::npos) << sign;
  const auto indep = msg({{"loops.C.branch.joint", "crank"}, {"loops.C.branch.sign", "positive"}});
  EXPECT_NE(indep.find("independent coordinate is set by `initial`"), std::string::npos) << indep;
}


// A branch names a joint the loop closes over: a flywheel geared to the crank is not one (no
// guess could move it to the other branch), and the refusal lists the loop's joints.
TEST(SceneYaml, LoopBranchJointMustBeOnTheLoop) {
  std::string yaml = kFourbar;
  yaml.replace(yaml.find("  - {name: rocker, mass_kg"), 0,
               "  - {name: wheel, mass_kg: 1.0, inertia_kgm2: 1.0e-2}\n");
  yaml.replace(yaml.find("loops:"), 0,
               "  - {name: wheel, type: revolute, parent: ground, parent_point: A, child: wheel}\n"
               "gears:\n  - {name: g, driver: crank, driven: wheel, ratio: 2}\n");
  const std::string on = std::string(yaml).replace(yaml.find("point_b: C}"), 11,
                                                    "point_b: C, branch: {joint: rocker, sign: positive}}");
  EXPECT_EQ(parse_scene(on, "t.yaml").loops[0].branch->joint, "rocker");
  const std::string off = std::string(yaml).replace(yaml.find("point_b: C}"), 11,
                                                     "point_b: C, branch: {joint: wheel, sign: positive}}");
  const SceneError e = refusal(off);
  EXPECT_EQ(e.field(), "loops[0].branch.joint") << e.what();
  EXPECT_NE(e.message().find("'wheel' is not a joint of loop 'C' (its joints: coupler, crank, rocker)"),
            std::string::npos)
      << e.what();
}

// Keys whose refusals come after loading (engine, calibration, reduced reactions) keep their
// lines, so those refusals can name them.
TEST(SceneYaml, KeysCheckedAfterLoadingKeepTheirLines) {
  const Scene s = parse_scene(R"(name: lines
bodies: [{name: crank, mass_kg: 1, inertia_kgm2: 0.01}]
joints: [{name: crank, type: revolute, parent: ground, parent_point: [0, 0], child: crank}]
independent: crank
independent_range_deg: [-10, 10]
outputs:
  reactions: all
initial:
  q_deg: 0
validation:
  calibrate: {cadence_Hz: 1, load: drive}
)",
                              "lines.yaml");
  EXPECT_EQ(s.line_of("independent_range_deg"), 5);
  EXPECT_EQ(s.line_of("outputs.reactions"), 7);
  EXPECT_EQ(s.line_of("initial"), 9);  // the block's first key
  EXPECT_EQ(s.line_of("validation.calibrate.load"), 11);
  EXPECT_EQ(s.line_of("loops.C.branch"), 0);
  EXPECT_EQ(where(s, "initial"), "lines.yaml:9: field 'initial'");
  EXPECT_EQ(where(s, "nothing"), "lines.yaml: field 'nothing'");
  const Scene rocker = load_scene("fourbar-rocker");
  EXPECT_EQ(rocker.line_of("loops.C.branch"), 25);
}

}  // namespace
}  // namespace rdyn::models

namespace rdyn::models {
namespace {

// independent_range (issue #10): degrees for a revolute (independent_range_deg) or SI
// (independent_range, as initial.q); checked finite, ordered, around the initial q.
TEST(SceneYaml, IndependentRangeIsReadInItsUnitAndChecked) {
  const std::string fb = std::string(kFourbar) + "initial: {q_deg: 30}\n";
  const Scene deg = parse_scene(fb + "independent_range_deg: [10, 120]\n", "test.yaml");
  ASSERT_TRUE(deg.independent_range);
  EXPECT_NEAR(deg.independent_range->min, 10 * kPi / 180, 1e-15);
  EXPECT_NEAR(deg.independent_range->max, 120 * kPi / 180, 1e-15);
  const Scene rad = parse_scene(fb + "independent_range: [0.1, 2.0]\n", "test.yaml");
  EXPECT_DOUBLE_EQ(rad.independent_range->max, 2.0);
  EXPECT_FALSE(parse_scene(fb, "test.yaml").independent_range);

  struct Case {
    std::string extra, field, words;
  };
  const Case cases[] = {
      {"independent_range_deg: [120, 10]\n", "independent_range_deg", "min < max"},
      {"independent_range: [0.2, 0.2]\n", "independent_range", "min < max"},
      {"independent_range_deg: [40, 120]\n", "initial.q", "outside independent_range"},
      {"independent_range_deg: [10, .nan]\n", "independent_range_deg[1]", "finite"},
      {"independent_range_deg: [10]\n", "independent_range_deg", "pair"},
      {"independent_range: [0.1, 2]\nindependent_range_deg: [10, 120]\n", "independent_range", "not both"},
      {"independent_range: [0.1, 1e7]\n", "independent_range[1]", "rad"},
  };
  for (const auto& c : cases) EXPECT_GT(expect_refused(fb + c.extra, c.field, c.words).line(), 0) << c.extra;
}

TEST(SceneYaml, PrismaticIndependentRangeIsInMetres) {
  const std::string sc = R"(
name: s
ground_points: {O: [0, 0]}
bodies:
  - {name: crank, mass_kg: 0.4, inertia_kgm2: 2.0e-4, points: {B: [0.05, 0]}}
  - {name: rod, mass_kg: 0.6, com_m: [0.08, 0], inertia_kgm2: 2.0e-3, points: {C: [0.2, 0]}}
  - {name: slider, mass_kg: 1.5, inertia_kgm2: 1.0e-3}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank, guess_deg: 60}
  - {name: rod, type: revolute, parent: crank, parent_point: B, child: rod, guess_deg: -72}
  - {name: slider, type: prismatic, parent: ground, parent_point: O, child: slider, axis: [1, 0], guess_m: 0.21}
loops:
  - {name: pin, body_a: rod, point_a: C, body_b: slider, point_b: [0, 0]}
independent: slider
initial: {q: 0.2}
)";
  EXPECT_DOUBLE_EQ(parse_scene(sc + "independent_range: [0.16, 0.24]\n", "t.yaml").independent_range->min, 0.16);
  const SceneError e = refusal(sc + "independent_range_deg: [10, 20]\n");
  EXPECT_EQ(e.field(), "independent_range_deg");
  EXPECT_NE(e.message().find("metres"), std::string::npos) << e.what();
}

// Profiled joint torques (models/load_profile.hpp): the two forms, the amplitude, and refusals
// naming file, line and field.
TEST(SceneYaml, ProfiledJointTorquesReadBothForms) {
  const std::string yaml = std::string(kFourbar) +
                           "  - {type: joint_torque, name: f, joint: crank, profile: {of: rocker, fourier: {a0: 2, a: "
                           "[0.5], b: [0, -1]}}}\n"
                           "  - {type: joint_torque, name: t, joint: crank, torque_Nm: -3, active_when: {joint: rocker, "
                           "rate: positive},\n"
                           "     profile: {of: crank, table_deg: [[-10, 1], [100, 4], [200, 2]]}}\n"
                           "  - {type: joint_torque, name: c, joint: crank, torque_Nm: 5}\n";
  const Scene s = parse_scene(yaml, "p.yaml");
  ASSERT_EQ(s.joint_torques.size(), 3u);
  const auto& f = s.joint_torques[0];
  ASSERT_TRUE(f.profile);
  EXPECT_EQ(f.value, 1.0);  // the amplitude multiplier defaults to 1
  EXPECT_EQ(f.profile->of, "rocker");
  EXPECT_NEAR(calc_joint_torque(f, 0.3), 2 + 0.5 * std::cos(0.3) - std::sin(0.6), 1e-15);
  const auto& t = s.joint_torques[1];
  ASSERT_TRUE(t.profile && t.profile->is_table() && t.active_when);
  EXPECT_NEAR(calc_joint_torque(t, 100 * kPi / 180), -12.0, 1e-12);  // amplitude × row
  EXPECT_NEAR(calc_joint_torque(t, 460 * kPi / 180), -12.0, 1e-12);  // one turn later
  EXPECT_FALSE(s.joint_torques[2].profile);
  EXPECT_EQ(calc_joint_torque(s.joint_torques[2], 1.0), 5.0);
}

TEST(SceneYaml, ProfileShapeIsPartOfTheSceneHashItsAmplitudeIsNot) {
  auto scene = [](const std::string& load) { return parse_scene(std::string(kFourbar) + load, "p.yaml"); };
  const auto a = scene("  - {type: joint_torque, name: f, joint: crank, profile: {of: rocker, fourier: {a0: 2}}}\n");
  const auto b = scene("  - {type: joint_torque, name: f, joint: crank, profile: {of: rocker, fourier: {a0: 3}}}\n");
  const auto c = scene(
      "  - {type: joint_torque, name: f, joint: crank, torque_Nm: 7, profile: {of: rocker, fourier: {a0: 2}}}\n");
  const auto d = scene("  - {type: joint_torque, name: f, joint: crank, profile: {of: crank, fourier: {a0: 2}}}\n");
  EXPECT_NE(scene_hash(a), scene_hash(b));  // the tabulated τ(θ) differs
  EXPECT_EQ(scene_hash(a), scene_hash(c));  // a calibration scales the amplitude without re-extraction
  EXPECT_NE(scene_hash(a), scene_hash(d));
}

TEST(SceneYaml, BadProfilesAreRefusedNamingLineAndField) {
  struct Bad {
    std::string load, field, message;
  };
  const std::string many = [] {
    std::string a;
    for (int i = 0; i < 65; ++i) a += i ? ", 0.1" : "0.1";
    return a;
  }();
  const std::vector<Bad> bad{
      {"profile: {of: rocker, fourier: {a0: .nan}}", "loads[1].profile.fourier.a0", "finite"},
      {"profile: {of: rocker, fourier: {a: [1, .inf]}}", "loads[1].profile.fourier.a[1]", "finite"},
      {"profile: {of: rocker, fourier: {b: [" + many + "]}}", "loads[1].profile.fourier.b", "at most 64"},
      {"profile: {of: rocker, fourier: {a0: 1}, table_deg: [[0, 1], [90, 1], [180, 1]]}", "loads[1].profile.fourier",
       "one of them"},
      {"profile: {of: rocker, table_deg: [[0, 1], [90, 1]]}", "loads[1].profile.table_deg", "3 to 720"},
      {"profile: {of: rocker, table_deg: [[0, 1], [90, 1], [90, 2]]}", "loads[1].profile.table_deg[2][0]",
       "increase"},
      {"profile: {of: rocker, table_deg: [[10, 1], [90, 1], [370, 2]]}", "loads[1].profile.table_deg[2][0]",
       "outside"},
      {"profile: {of: rocker, table_deg: [[-10, 1], [90, 1], [350, 2]]}", "loads[1].profile.table_deg[2][0]",
       "one turn"},
      {"profile: {of: rocker, table_deg: [[0, 1], [90], [180, 2]]}", "loads[1].profile.table_deg[1]", "pair"},
      {"profile: {of: rocker, table_deg: [[0, 1], [90, 1e300], [180, 2]]}", "loads.p.profile.table_deg[1][1]",
       "finite with"},
      {"profile: {of: nosuch, fourier: {a0: 1}}", "loads.p.profile.of", "unknown joint"},
      {"profile: {of: rocker, fourier: {a0: 1}, extra: 2}", "loads[1].profile.extra", "unknown key"},
      {"torque_Nm: 3.0e5, profile: {of: rocker, fourier: {a0: 3, a: [2]}}", "loads.p.torque_Nm", "can reach 1.5e+06"},
  };
  for (const auto& b : bad) {
    const std::string line = "  - {type: joint_torque, name: p, joint: crank, " + b.load + "}\n";
    expect_refused(std::string(kFourbar) + line, b.field, b.message, line);
  }
}

TEST(SceneYaml, ProfileOfAPrismaticJointIsRefused) {
  std::ifstream in(std::string(RDYN_SCENES) + "/slider-crank.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const std::string yaml =
      with(text.str(), "loads:\n",
           "loads:\n  - {type: joint_torque, name: p, joint: crank, profile: {of: slider, fourier: {a0: 1}}}\n");
  const SceneError e = refusal(yaml);
  EXPECT_EQ(e.field(), "loads.p.profile.of") << e.what();
  EXPECT_NE(e.message().find("revolute"), std::string::npos) << e.what();
}


// Radian keys (what scene_to_yaml writes, models/scene_write.hpp): read exactly as given, one
// unit per angle, none on a prismatic joint.
TEST(SceneYaml, JointAnglesInRadiansReadExactly) {
  const std::string y = with(kFourbar, "guess_deg: 90}", "offset_rad: 0.1234567890123, guess_rad: 1.5707}");
  const Scene s = parse_scene(y, "t.yaml");
  EXPECT_EQ(s.joints[2].offset_rad, 0.1234567890123);
  EXPECT_EQ(s.joints[2].guess, 1.5707);
  const SceneError both = refusal(with(kFourbar, "guess_deg: 90}", "guess_deg: 90, guess_rad: 1.5}"));
  EXPECT_EQ(both.field(), "joints[2].guess_rad") << both.what();
  EXPECT_NE(both.message().find("not both"), std::string::npos) << both.what();
  EXPECT_EQ(both.line(), line_in(kFourbar, "name: rocker, type"));
  const SceneError big = refusal(with(kFourbar, "guess_deg: 90}", "guess_rad: 2.0e6}"));
  EXPECT_EQ(big.field(), "joints[2].guess_rad") << big.what();
}

TEST(SceneYaml, PrismaticJointRefusesRadianKeys) {
  std::ifstream in(std::string(RDYN_SCENES) + "/slider-crank.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const SceneError e = refusal(with(text.str(), "guess_m: 0.2417}", "guess_m: 0.2417, offset_rad: 0.1}"));
  EXPECT_NE(e.field().find("type"), std::string::npos) << e.what();
  EXPECT_NE(e.message().find("guess_m"), std::string::npos) << e.what();
}

// table_rad: the same rows in radians give the same spline (to the rounding of x·π/180),
// checked in degrees like table_deg.
TEST(SceneYaml, ProfileTableInRadiansMatchesDegrees) {
  auto scene = [](const std::string& table) {
    return parse_scene(std::string(kFourbar) + "  - {type: joint_torque, name: p, joint: crank, profile: {of: crank, " +
                           table + "}}\n",
                       "t.yaml");
  };
  const Scene deg = scene("table_deg: [[-10, 1], [100, 4], [200, 2]]");
  const Scene rad = scene(fmt::format("table_rad: [[{}, 1], [{}, 4], [{}, 2]]", -10 * kPi / 180, 100 * kPi / 180,
                                      200 * kPi / 180));
  const auto& pr = *rad.joint_torques[0].profile;
  EXPECT_EQ(pr.table_theta_rad[1], 100 * kPi / 180);  // as written
  for (double th = -4; th < 4; th += 0.37)
    EXPECT_NEAR(calc_profile(pr, th), calc_profile(*deg.joint_torques[0].profile, th), 1e-12) << th;
  const std::string close = "table_rad: [[0, 1], [0.0001, 4], [3, 2]]";  // 0.0057° apart
  const SceneError e = refusal(std::string(kFourbar) +
                               "  - {type: joint_torque, name: p, joint: crank, profile: {of: crank, " + close + "}}\n");
  EXPECT_EQ(e.field(), "loads[1].profile.table_rad[1][0]") << e.what();
  const SceneError two = refusal(std::string(kFourbar) +
                                 "  - {type: joint_torque, name: p, joint: crank, profile: {of: crank, table_deg: [[0, "
                                 "1], [90, 1], [180, 1]], table_rad: [[0, 1], [1, 1], [2, 1]]}}\n");
  EXPECT_NE(two.message().find("one of them"), std::string::npos) << two.what();
}

// A direction or axis already of unit length to rounding is kept as written (so a written
// scene reads back bit for bit); any other is normalised.
TEST(SceneYaml, UnitVectorsAreKeptAsWritten) {
  // A normalised vector whose rounded length is not 1: dividing by it again would move it.
  double x = 1, y = 0;
  for (int a = 1; a < 1000 && std::hypot(x, y) == 1.0; ++a) {
    const double len = std::hypot(a, 7.0);
    x = a / len, y = 7.0 / len;
  }
  ASSERT_NE(std::hypot(x, y), 1.0);
  ASSERT_NEAR(std::hypot(x, y), 1.0, 4e-16);
  const Scene s = parse_scene(std::string(kFourbar) + fmt::format(
                                                          "outputs:\n  constraint_forces:\n    - {{name: u, joint: rocker, "
                                                          "direction: [{}, {}]}}\n    - {{name: v, joint: rocker, "
                                                          "direction: [3, 4]}}\n",
                                                          x, y),
                              "t.yaml");
  EXPECT_EQ(s.outputs.constraint_forces[0].direction.x, x);
  EXPECT_EQ(s.outputs.constraint_forces[0].direction.y, y);
  EXPECT_NEAR(s.outputs.constraint_forces[1].direction.x, 0.6, 1e-16);
  EXPECT_NEAR(s.outputs.constraint_forces[1].direction.y, 0.8, 1e-16);
}

// Point forces (muscle-like tensions between two points): the fields, ground as a body, named
// points, the profile and gate, the hash (geometry and shape in, tension out), and refusals.
TEST(SceneYaml, PointForcesReadPointsProfileAndGate) {
  const std::string yaml = std::string(kFourbar) +
                           "  - {type: point_force, name: m, body_a: ground, point_a: D, body_b: crank, point_b: B,\n"
                           "     force_N: 40, active_when: {joint: crank, rate: negative},\n"
                           "     profile: {of: rocker, fourier: {a0: 1, b: [0.5]}}}\n"
                           "  - {type: point_force, name: c, body_a: coupler, point_a: [0.1, 0.02], body_b: rocker, "
                           "point_b: C, force_N: -3}\n";
  const Scene s = parse_scene(yaml, "p.yaml");
  ASSERT_EQ(s.point_forces.size(), 2u);
  const auto& m = s.point_forces[0];
  EXPECT_EQ(m.body_a, "ground");
  EXPECT_EQ(m.point_a.x, 0.3);   // ground point D
  EXPECT_EQ(m.point_b.x, 0.08);  // crank point B
  ASSERT_TRUE(m.active_when && m.profile);
  EXPECT_EQ(m.active_when->sign, -1);
  EXPECT_NEAR(calc_point_force_tension(m, 0.4), 40 * (1 + 0.5 * std::sin(0.4)), 1e-12);
  EXPECT_EQ(calc_point_force_tension(s.point_forces[1], 0.4), -3.0);  // a push: negative tension
  EXPECT_EQ(s.point_forces[1].point_a.y, 0.02);
}

TEST(SceneYaml, PointForceHashHoldsGeometryAndShapeNotTheTension) {
  auto scene = [](const std::string& load) { return parse_scene(std::string(kFourbar) + load, "p.yaml"); };
  const std::string base = "  - {type: point_force, name: m, body_a: ground, point_a: D, body_b: crank, point_b: B, ";
  const auto a = scene(base + "force_N: 10}\n");
  const auto b = scene(base + "force_N: 25}\n");
  const auto c = scene("  - {type: point_force, name: m, body_a: ground, point_a: A, body_b: crank, point_b: B, "
                       "force_N: 10}\n");
  const auto d = scene(base + "profile: {of: crank, fourier: {a0: 2}}}\n");
  const auto e = scene(base + "profile: {of: crank, fourier: {a0: 3}}}\n");
  const auto g = scene(base + "force_N: 10, active_when: {joint: crank, rate: positive}}\n");
  EXPECT_EQ(scene_hash(a), scene_hash(b));  // the tension is calibrated without re-extraction
  EXPECT_NE(scene_hash(a), scene_hash(c));
  EXPECT_NE(scene_hash(d), scene_hash(e));
  EXPECT_NE(scene_hash(a), scene_hash(g));
  EXPECT_NE(scene_hash(a), scene_hash(scene("")));
}

TEST(SceneYaml, BadPointForcesAreRefusedNamingLineAndField) {
  struct Bad {
    std::string load, field, message;
  };
  const std::string ok = "body_a: ground, point_a: D, body_b: crank, point_b: B";
  const std::vector<Bad> bad{
      {"body_a: nosuch, point_a: [0, 0], body_b: crank, point_b: B, force_N: 1", "loads[1].body_a", "unknown body"},
      {"body_a: ground, point_a: Z, body_b: crank, point_b: B, force_N: 1", "loads[1].point_a", "no point named 'Z'"},
      {"body_a: ground, point_a: D, body_b: crank, point_b: C, force_N: 1", "loads[1].point_b", "no point named 'C'"},
      {ok + ", force_N: .nan", "loads[1].force_N", "finite"},
      {ok + ", force_N: 2.0e6", "loads.p.force_N", "1e+06"},
      {ok + ", force_N: 4.0e5, profile: {of: crank, fourier: {a0: 2, a: [1]}}", "loads.p.force_N", "can reach 1.2e+06"},
      {ok + ", profile: {of: nosuch, fourier: {a0: 1}}", "loads.p.profile.of", "unknown joint"},
      {ok + ", force_N: 1, active_when: {joint: nosuch, rate: positive}", "loads.p.active_when.joint", "unknown joint"},
      {ok + ", force_N: 1, active_when: {joint: crank, rate: up}", "loads[1].active_when.rate", "positive or negative"},
      {ok, "loads[1].force_N", "give force_N"},
      {ok + ", force_N: 1, torque_Nm: 2", "loads[1].torque_Nm", "unknown key"},
      {"body_a: crank, point_a: [0, 0], body_b: crank, point_b: B, force_N: 1", "loads.p.body_b", "one body"},
      {"body_a: ground, point_a: [0, 2000], body_b: crank, point_b: B, force_N: 1", "loads.p.point_a[1]", "1000"},
  };
  for (const auto& b : bad) {
    const std::string line = "  - {type: point_force, name: p, " + b.load + "}\n";
    expect_refused(std::string(kFourbar) + line, b.field, b.message, line);
  }
}

}  // namespace
}  // namespace rdyn::models

namespace rdyn::models {
namespace {

// The byte-order mark and CR-only line ends go; CRLF and plain text stay as they are.
TEST(SceneYaml, NormaliseTextEncodingDropsTheMarkAndEndsCrOnlyLines) {
  EXPECT_EQ(normalise_text_encoding("\xEF\xBB\xBFt,q\n0,1\n"), "t,q\n0,1\n");
  EXPECT_EQ(normalise_text_encoding("t,q\r0,1\r"), "t,q\n0,1\n");
  EXPECT_EQ(normalise_text_encoding("t,q\r\n0,1\r\n"), "t,q\r\n0,1\r\n");
  EXPECT_EQ(normalise_text_encoding(""), "");
}

// read_scene_text reads in chunks of 16 kB: a scene longer than several chunks comes back byte
// for byte and loads as the short one; a file larger than a scene may be is cut one byte past
// the limit, so parse_scene refuses it by its size (and /dev/zero cannot exhaust memory).
TEST(SceneYaml, ReadSceneTextKeepsLongScenesWholeAndCutsOversizedOnesPastTheLimit) {
  const std::string base = read_scene_text("fourbar");
  const std::string padded = base + "\n# " + std::string(70000, 'x') + "\n";  // 4+ chunks
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("rdyn_read_{}", ::getpid());
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "long.yaml").string();
  std::ofstream(path, std::ios::binary) << padded;
  EXPECT_EQ(read_scene_text(path), padded);
  EXPECT_EQ(scene_hash(load_scene(path)), scene_hash(load_scene("fourbar")));
  const std::string huge_path = (dir / "huge.yaml").string();
  std::ofstream(huge_path, std::ios::binary) << base << "# " << std::string(yaml::kMaxSceneBytes, 'y') << "\n";
  const std::string cut = read_scene_text(huge_path);
  EXPECT_EQ(cut.size(), yaml::kMaxSceneBytes + 1);
  EXPECT_EQ(cut.compare(0, base.size(), base), 0);
  try {
    load_scene(huge_path);
    ADD_FAILURE() << "an oversized scene loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("too large for a scene"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::models
