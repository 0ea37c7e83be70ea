// The load a calibration sets (validate/analysis/calibration_load.cpp): which loads a name
// selects, with which sign and unit, and the magnitude applied to a scene keeps every sign.
#include "validate/analysis/calibration_load.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

std::string flywheel(const std::string& loads) {
  return "name: flywheel\n"
         "bodies: [{name: wheel, mass_kg: 2.0, inertia_kgm2: 0.05}]\n"
         "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]\n"
         "independent: wheel\n"
         "loads:\n"
         "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}\n" +
         loads + "initial: {q_deg: 0, qdot: -5.0}\n";
}

CalibrationOptions load_named(const std::string& name) {
  CalibrationOptions opt;
  opt.load = name;
  opt.load_field = "--load";
  return opt;
}

TEST(CalibrationLoad, WithoutANameEveryJointTorqueIsScaledKeepingItsSign) {
  const auto scene = models::parse_scene(
      flywheel("  - {type: joint_torque, name: a, joint: wheel, torque_Nm: -0.3}\n"
               "  - {type: joint_torque, name: b, joint: wheel, torque_Nm: 0.1}\n"),
      "f.yaml");
  const Selection sel = select_load(scene, CalibrationOptions{});
  ASSERT_EQ(sel.entries.size(), 2u);
  EXPECT_EQ(sel.name, "a+b");
  EXPECT_EQ(sel.unit, "N·m");
  const auto scaled = with_load(scene, sel, 2.5, NAN);
  EXPECT_EQ(scaled.joint_torques[0].value, -2.5);
  EXPECT_EQ(scaled.joint_torques[1].value, 2.5);
  EXPECT_EQ(scaled.resistances[0].coefficient, 0.02);  // NaN: unchanged
  EXPECT_EQ(with_load(scene, sel, 1.0, 0.07).resistances[0].coefficient, 0.07);
}

// Without a name, joint torques in N·m and N would share one magnitude (a Whitworth's crank
// torque and ram force both 1.7): refused, as `--load a+b` refuses mixed units, naming both.
TEST(CalibrationLoad, WithoutANameJointTorquesInTwoUnitsAreRefused) {
  const auto slider = models::load_scene("slider-crank");  // a motor, and a joint torque in N
  models::Scene scene = slider;
  scene.joint_torques.insert(scene.joint_torques.begin(), scene.joint_torques[0]);
  scene.joint_torques[0].name = "crank_drive";
  scene.joint_torques[0].joint = "crank";
  try {
    select_load(scene, CalibrationOptions{});
    ADD_FAILURE() << "mixed units accepted";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "validation.calibrate.load");
    EXPECT_NE(e.message().find("'crank_drive' is in N·m while 'piston_load' is in N"), std::string::npos)
        << e.message();
  }
  CalibrationOptions named;
  named.load = "crank_drive";
  named.load_field = "--load";
  EXPECT_EQ(select_load(scene, named).unit, "N·m");  // a name chooses one
}

TEST(CalibrationLoad, AMotorTakesItsNoLoadSpeedsSign) {
  const auto scene = models::parse_scene(
      flywheel("  - {type: motor, name: m, joint: wheel, stall_torque_Nm: -1.0, no_load_speed_rad_s: -30}\n"),
      "f.yaml");
  const Selection sel = select_load(scene, load_named("m"));
  ASSERT_EQ(sel.entries.size(), 1u);
  EXPECT_TRUE(sel.entries[0].motor);
  EXPECT_EQ(sel.entries[0].sign, -1.0);
  EXPECT_EQ(sel.kind, "motor_stall_torque");
  EXPECT_EQ(with_load(scene, sel, 4.0, NAN).motors[0].stall_torque, -4.0);
}

TEST(CalibrationLoad, NamesThatAreNotDriveLoadsAreRefusedNamingTheField) {
  const auto scene = models::parse_scene(
      flywheel("  - {type: joint_torque, name: a, joint: wheel, torque_Nm: 0.3}\n"), "f.yaml");
  for (const char* bad : {"drag", "nosuch", "a+a", "a+"}) {
    try {
      select_load(scene, load_named(bad));
      ADD_FAILURE() << bad << " was accepted";
    } catch (const models::SceneError& e) {
      EXPECT_EQ(e.field(), "--load") << bad;
    }
  }
}

}  // namespace
}  // namespace rdyn::validate
