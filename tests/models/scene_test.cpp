// check_scene: names, ranges and topology of a scene built in code (no YAML), each refused
// with the field that is wrong.
#include "models/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace rdyn::models {
namespace {

// Two wheels on ground axles geared 1:2 (joints 2 − gears 1 = 1 degree of freedom), with one
// load of each type and a validation block: every check has something to look at.
Scene geared_pair() {
  Scene s;
  s.name = "geared-pair";
  s.source_file = "pair.yaml";
  s.bodies = {{"wheel", 2.0, {0, 0}, 0.04, {{"rim", {0.2, 0}}}}, {"pinion", 0.5, {0, 0}, 1e-3, {}}};
  s.ground_points = {{"A", {0, 0}}, {"B", {0.3, 0}}};
  s.joints = {
      {"wheel", JointType::Revolute, kGround, "wheel", {0, 0}, {0, 0}, {1, 0}, 0.0, 0.0},
      {"pinion", JointType::Revolute, kGround, "pinion", {0.3, 0}, {0, 0}, {1, 0}, 0.0, 0.0}};
  s.gears = {{"mesh", "wheel", "pinion", -2.0}};
  s.independent = "wheel";
  s.joint_torques = {{"drive", "wheel", 1.0, std::nullopt}};
  s.resistances = {{"brake", "pinion", ResistanceLaw::Viscous, 1e-3}};
  s.springs = {{"spring", "wheel", {0.2, 0}, kGround, {0.2, 0.1}, 100.0, 0.1}};
  s.motors = {{"motor", "wheel", 2.0, 30.0}};
  s.outputs.constraint_forces = {{"pin", "pinion", {1, 0}}};
  s.validation.thresholds = {{"qdot", 10.0, "", 0.01}, {"pin", 0.5, "akima", 0.05}};
  return s;
}

// The field check_scene names for the scene after `edit`; empty when it passes.
std::string refused_field(const std::function<void(Scene&)>& edit) {
  Scene s = geared_pair();
  edit(s);
  try {
    check_scene(s);
  } catch (const SceneError& e) {
    EXPECT_EQ(e.file(), "pair.yaml");
    return e.field();
  }
  return "";
}

TEST(CheckScene, TheReferenceSceneIsAccepted) {
  EXPECT_EQ(refused_field([](Scene&) {}), "");
}

TEST(CheckScene, NamesFollowThePattern) {
  for (const char* good : {"a", "_x", "knee_r", "slider-crank", "A1", "x-1_y"})
    EXPECT_TRUE(is_valid_name(good)) << good;
  EXPECT_TRUE(is_valid_name(std::string(64, 'a')));
  EXPECT_FALSE(is_valid_name(std::string(65, 'a')));
  for (const char* bad :
       {"", "1a", "-a", "a b", "a,b", "a\"b", "a'b", "a\nb", "a/b", "a<b", "a.b", "a;b", "é"})
    EXPECT_FALSE(is_valid_name(bad)) << bad;
}

TEST(CheckScene, BadOrDuplicateNamesAreRefusedPerKind) {
  EXPECT_EQ(refused_field([](Scene& s) { s.name = "my scene"; }), "name");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[1].name = "pin,ion"; }), "bodies[1].name");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[1].name = "ground"; }), "bodies[1].name");
  EXPECT_EQ(refused_field([](Scene& s) { s.joints[1].name = "wheel"; }), "joints[1].name");
  EXPECT_EQ(refused_field([](Scene& s) { s.gears.push_back(s.gears[0]); }), "gears[1].name");
  EXPECT_EQ(refused_field([](Scene& s) { s.motors[0].name = "drive"; }),
            "loads");  // same as the torque
  EXPECT_EQ(refused_field([](Scene& s) { s.outputs.constraint_forces[0].name = "a<b>"; }),
            "outputs.constraint_forces[0].name");
  EXPECT_EQ(refused_field([](Scene& s) {
              s.bodies[0].points["r/m"] = {0, 0};
            }),
            "bodies.wheel.points");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[1].quantity = "nosuch"; }),
            "validation.thresholds[1].quantity");
  EXPECT_EQ(refused_field([](Scene& s) {
              s.outputs.bodies = {"wheel", "wheel"};
            }),
            "outputs.bodies[1]");
}

TEST(CheckScene, MassesInertiasAndPointsHaveRanges) {
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].mass_kg = 0.0; }), "bodies.wheel.mass_kg");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].mass_kg = 1e308; }), "bodies.wheel.mass_kg");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].mass_kg = NAN; }), "bodies.wheel.mass_kg");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].inertia_kgm2 = -1.0; }),
            "bodies.wheel.inertia_kgm2");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].inertia_kgm2 = 2e6; }),
            "bodies.wheel.inertia_kgm2");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].com_m.y = 1001.0; }), "bodies.wheel.com_m[1]");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].points["rim"].x = INFINITY; }),
            "bodies.wheel.points.rim[0]");
  EXPECT_EQ(refused_field([](Scene& s) { s.ground_points["B"].x = -2e3; }), "ground_points.B[0]");
  EXPECT_EQ(refused_field([](Scene& s) { s.joints[1].parent_point.x = 1e300; }),
            "joints.pinion.parent_point[0]");
  EXPECT_EQ(refused_field([](Scene& s) { s.joints[1].guess = 2e6; }), "joints.pinion.guess");
  EXPECT_EQ(refused_field([](Scene& s) { s.gravity.g_m_s2.y = -1e4; }), "gravity.g_m_s2[1]");
  // The bounds themselves are allowed.
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].mass_kg = limits::kMaxMass_kg; }), "");
  EXPECT_EQ(refused_field([](Scene& s) { s.bodies[0].com_m.y = -limits::kMaxCoordinate_m; }), "");
}

TEST(CheckScene, AGearCouplingAJointToItselfIsRefused) {
  // Before, joints (2) − gears (1) = 1 passed the mobility count, and two free wheels ran.
  EXPECT_EQ(refused_field([](Scene& s) { s.gears[0].driven = "wheel"; }), "gears.mesh.driven");
}

TEST(CheckScene, GearRatiosAreBounded) {
  EXPECT_EQ(refused_field([](Scene& s) { s.gears[0].ratio = 0.0; }), "gears.mesh.ratio");
  EXPECT_EQ(refused_field([](Scene& s) { s.gears[0].ratio = -5e-4; }), "gears.mesh.ratio");
  EXPECT_EQ(refused_field([](Scene& s) { s.gears[0].ratio = 1001.0; }), "gears.mesh.ratio");
  EXPECT_EQ(refused_field([](Scene& s) { s.gears[0].ratio = -1000.0; }), "");
}

TEST(CheckScene, MotorSpeedMustHaveTheSignOfItsTorque) {
  EXPECT_EQ(refused_field([](Scene& s) { s.motors[0].no_load_speed = -30.0; }),
            "loads.motor.no_load_speed_rad_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.motors[0].no_load_speed = 0.0; }),
            "loads.motor.no_load_speed_rad_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.motors[0].no_load_speed = 2e4; }),
            "loads.motor.no_load_speed_rad_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.motors[0].stall_torque = NAN; }),
            "loads.motor.stall_torque_Nm");
  // A motor driving backwards: both negative.
  EXPECT_EQ(refused_field([](Scene& s) { s.motors[0] = {"motor", "wheel", -2.0, -30.0}; }), "");
}

TEST(CheckScene, ResistanceIsBoundedByItsBodysInertia) {
  // pinion: I = 1e-3 kg·m², τ_min = 1e-6 s → c ≤ 1000 (N·m·s for the viscous law).
  EXPECT_EQ(refused_field([](Scene& s) { s.resistances[0].coefficient = 1000.0; }), "");
  EXPECT_EQ(refused_field([](Scene& s) { s.resistances[0].coefficient = 1000.001; }),
            "loads.brake.coefficient");
  EXPECT_EQ(refused_field([](Scene& s) { s.resistances[0].coefficient = -1e-9; }),
            "loads.brake.coefficient");
}

TEST(CheckScene, SpringsAndTorquesAreBounded) {
  EXPECT_EQ(refused_field([](Scene& s) { s.springs[0].stiffness_N_per_m = -1.0; }),
            "loads.spring.stiffness_N_per_m");
  EXPECT_EQ(refused_field([](Scene& s) { s.springs[0].stiffness_N_per_m = 2e9; }),
            "loads.spring.stiffness_N_per_m");
  EXPECT_EQ(refused_field([](Scene& s) { s.springs[0].rest_length_m = -0.1; }),
            "loads.spring.rest_length_m");
  EXPECT_EQ(refused_field([](Scene& s) { s.joint_torques[0].value = 1e7; }),
            "loads.drive.torque_Nm");
}

TEST(CheckScene, SimulationSettingsHaveRanges) {
  EXPECT_EQ(refused_field([](Scene& s) { s.simulation.duration_s = 0.0; }),
            "simulation.duration_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.simulation.duration_s = 2e5; }),
            "simulation.duration_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.simulation.output_interval_s = 1e-7; }),
            "simulation.output_interval_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.simulation.output_interval_s = 6.0; }),
            "simulation.output_interval_s");
  // 1000 s at 1e-5 s: 1e8 rows, more than 1e7.
  EXPECT_EQ(refused_field([](Scene& s) {
              s.simulation = {1000.0, 1e-5, 1e-9};
            }),
            "simulation.output_interval_s");
  EXPECT_EQ(refused_field([](Scene& s) { s.simulation.tolerance = 1e-15; }),
            "simulation.tolerance");
  EXPECT_EQ(refused_field([](Scene& s) { s.simulation.tolerance = 0.5; }), "simulation.tolerance");
  EXPECT_EQ(refused_field([](Scene& s) { s.initial.qdot = 1.5e4; }), "initial.qdot");
  EXPECT_EQ(refused_field([](Scene& s) { s.initial.q = NAN; }), "initial.q");
}

TEST(CheckScene, ValidationSettingsHaveRanges) {
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[0].max_error = 0.0; }),
            "validation.thresholds[0].max_error");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[0].max_error = 1.5; }),
            "validation.thresholds[0].max_error");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[0].grid_deg = 0.01; }),
            "validation.thresholds[0].grid_deg");
  EXPECT_EQ(refused_field(
                [](Scene& s) { s.validation.thresholds[0].grid_deg = 7.0; }),  // 360/7 not whole
            "validation.thresholds[0].grid_deg");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[0].grid_deg = 0.05; }),
            "");  // 7200 steps
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[0].grid_deg = 90.0; }), "");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.thresholds[0].interpolation = "a b"; }),
            "validation.thresholds[0].interpolation");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.reference_tolerance = 1e-2; }),
            "validation.reference_tolerance");
  EXPECT_EQ(refused_field([](Scene& s) { s.validation.duration_s = -1.0; }),
            "validation.duration_s");
  EXPECT_EQ(refused_field([](Scene& s) {
              s.validation.calibrate_cadence_Hz = 25.0, s.validation.calibrate_power_W = 100;
            }),
            "validation.calibrate.cadence_Hz");
  EXPECT_EQ(refused_field([](Scene& s) {
              s.validation.calibrate_cadence_Hz = 1.0, s.validation.calibrate_power_W = 2e5;
            }),
            "validation.calibrate.power_W");
}

// A threshold may judge a requested joint output (issue #23: one on R_crank_x was refused), not
// one the scene does not ask for.
TEST(CheckScene, ThresholdsMayNameRequestedJointOutputs) {
  auto with = [](const std::string& quantity, bool request) {
    return refused_field([&](Scene& s) {
      if (request) s.outputs.reactions = {"pinion"}, s.outputs.joints = {"wheel"}, s.outputs.shaking = true;
      s.validation.thresholds[0].quantity = quantity;
    });
  };
  for (const char* q : {"R_pinion_x", "R_pinion_y", "q_wheel", "qddot_wheel", "shaking_M"}) {
    EXPECT_EQ(with(q, true), "") << q;
    EXPECT_EQ(with(q, false), "validation.thresholds[0].quantity") << q;
  }
  EXPECT_EQ(with("R_wheel_x", true), "validation.thresholds[0].quantity");  // not requested
  EXPECT_EQ(joint_output_names(geared_pair()).size(), 0u);
}

TEST(FixedSpeedRatio, GearsAndUnknownJointsBeforeTheChecks) {
  Scene s = geared_pair();
  EXPECT_EQ(fixed_speed_ratio(s, "wheel"), 1.0);
  EXPECT_EQ(fixed_speed_ratio(s, "pinion"), -2.0);
  // The same gear written the other way round (the pinion drives the wheel at −1/2): a press's
  // motor geared to its crank as `driver: motor, driven: crank, ratio: 0.04` was refused.
  Scene reversed = s;
  std::swap(reversed.gears[0].driver, reversed.gears[0].driven);
  reversed.gears[0].ratio = -0.5;
  EXPECT_EQ(fixed_speed_ratio(reversed, "pinion"), -2.0);
  EXPECT_EQ(fixed_speed_ratio(reversed, "wheel"), 1.0);
  // The reader asks before check_scene has run: a gear whose driver names no joint (and an
  // independent coordinate naming the same) dereferenced a null joint.
  s.independent = "nosuch";
  s.gears[0].driver = "nosuch";
  EXPECT_EQ(fixed_speed_ratio(s, "pinion"), std::nullopt);
}

TEST(CheckScene, ListsAreBounded) {
  EXPECT_EQ(refused_field([](Scene& s) {
              for (int i = 0; i < 1000; ++i)
                s.bodies.push_back({"b" + std::to_string(i), 1.0, {}, 1.0, {}});
            }),
            "bodies");
}

}  // namespace
}  // namespace rdyn::models
