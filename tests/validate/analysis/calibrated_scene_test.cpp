// Writing a calibrated scene (validate/analysis/calibrated_scene.cpp): the calibrated magnitude goes
// where the scene's text lists the load (profiled torques' amplitudes, point forces named together),
// read back by the scene reader. The whole calibrate → write → simulate route: calibrate_test.cpp.
#include "validate/analysis/calibrated_scene.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

TEST(CalibratedScene, WrittenSceneScalesProfiledLoadsWhereTheSceneListsThem) {
  // bicycle-profile: hip_torque_Nm 0 (no generated torques) and two profiled hip torques under
  // `loads`: the amplitudes are rewritten there, the generator's hip torque stays 0 (setting it
  // would add constant hip torques beside the profiles).
  std::ifstream in(std::string(RDYN_SCENES) + "/bicycle-profile.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const auto scene = models::parse_scene(text.str(), "bicycle-profile.yaml");
  CalibrationResult r;
  r.torque_Nm = r.load_value = 12.5;  // every joint torque together: the magnitude each gets
  r.steady_qdot = 6.0;
  const std::string out = calibrated_scene_yaml("bicycle-profile.yaml", text.str(), {}, scene, CalibrationOptions{}, r);
  const auto again = models::parse_scene(out, "written.yaml");
  ASSERT_EQ(again.joint_torques.size(), 2u);
  for (const auto& t : again.joint_torques) {
    EXPECT_TRUE(t.profile) << t.name;
    EXPECT_EQ(t.value, 12.5) << t.name;
  }
}

TEST(CalibratedScene, WrittenSceneScalesPointForcesNamedTogether) {
  // bicycle-muscle: two profiled point forces under `loads`, calibrated together by name; both
  // tensions are rewritten (the profile's amplitude), nothing of the generator.
  std::ifstream in(std::string(RDYN_SCENES) + "/bicycle-muscle.yaml");
  std::stringstream text;
  text << in.rdbuf();
  const auto scene = models::parse_scene(text.str(), "bicycle-muscle.yaml");
  CalibrationOptions opt = calibration_options_of(scene, 0.0, 0.0, "");
  EXPECT_EQ(opt.load, "gluteus_r+gluteus_l");  // from its validation.calibrate block
  CalibrationResult r;
  r.load_value = 512.5;  // names joined by '+': the magnitude each gets
  r.steady_qdot = 6.0;
  const auto again =
      models::parse_scene(calibrated_scene_yaml("bicycle-muscle.yaml", text.str(), {}, scene, opt, r), "w.yaml");
  ASSERT_EQ(again.point_forces.size(), 2u);
  for (const auto& f : again.point_forces) {
    EXPECT_TRUE(f.profile && f.active_when) << f.name;
    EXPECT_EQ(f.value, 512.5) << f.name;
  }
  EXPECT_TRUE(again.joint_torques.empty());
  EXPECT_EQ(again.initial.qdot, 6.0);
}

// With a power, the header says how the resistance was written: a scene that gives its
// coefficient gets the calibrated coefficient (and no remark about a nominal power_W it does not
// have: the Jansen leg's header said "its power_W is nominal"); a `dissipates` block gets a
// nominal power_W, and the remark says so.
TEST(CalibratedScene, HeaderNamesTheNominalPowerOnlyWhereTheSceneHoldsOne) {
  // The Jansen leg of issue #23: a drive torque and a viscous load given by its coefficient.
  std::ifstream in(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/jansen-leg.yaml");
  std::stringstream text;
  text << in.rdbuf();
  CalibrationOptions opt;
  opt.cadence_hz = 1.0, opt.power_w = 2.0;
  CalibrationResult r;
  r.load_value = r.torque_Nm = 0.5, r.resistance_coefficient = 0.0481, r.steady_qdot = 6.0;
  r.mean_cadence_hz_reduced = r.mean_cadence_hz_full = 1.0;
  const auto scene = models::parse_scene(text.str(), "jansen-leg.yaml");
  const std::string coef = calibrated_scene_yaml("jansen-leg.yaml", text.str(), {}, scene, opt, r);
  EXPECT_EQ(coef.find("nominal"), std::string::npos) << coef.substr(0, 400);
  EXPECT_NE(coef.find("coefficient set to 0.0481"), std::string::npos) << coef.substr(0, 400);
  EXPECT_EQ(models::parse_scene(coef, "w.yaml").resistances.at(0).coefficient, 0.0481);
  // The same bearing given by what it dissipates: the header explains the nominal power_W.
  std::string dis = text.str();
  const std::string from = "law: viscous, coefficient: 0.5}";
  ASSERT_NE(dis.find(from), std::string::npos);
  dis.replace(dis.find(from), from.size(), "law: viscous, dissipates: {power_W: 1.0, cadence_Hz: 1.0}}");
  const auto dscene = models::parse_scene(dis, "jansen-leg.yaml");
  const std::string nom = calibrated_scene_yaml("jansen-leg.yaml", dis, {}, dscene, opt, r);
  EXPECT_NE(nom.find("power_W is nominal"), std::string::npos) << nom.substr(0, 400);
  EXPECT_NEAR(models::parse_scene(nom, "w.yaml").resistances.at(0).coefficient, 0.0481, 1e-12);
}

TEST(CalibratedScene, AGeneratedLoadNamedAloneCannotBeWrittenTheWholeDriveCan) {
  // The bicycle's hip torques are made by its generator (bicycle_leg): no YAML key holds one of
  // them, only the generator's hip_torque_Nm (every joint torque together).
  const auto bike = models::load_scene("bicycle");
  const std::string text = models::read_scene_text("bicycle");
  try {
    check_writable(text, bike, calibration_options_of(bike, 0, 0, "hip_torque_r"));
    ADD_FAILURE() << "a generated load was accepted";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "--write-scene");
    EXPECT_NE(std::string(e.what()).find("generator"), std::string::npos) << e.what();
  }
  CalibrationResult r;
  r.load_value = 70.0;
  r.steady_qdot = 6.5;
  r.steady_q = 0.25;
  const auto again = models::parse_scene(
      calibrated_scene_yaml("bicycle", text, {}, bike, calibration_options_of(bike, 0, 0, ""), r), "w.yaml");
  ASSERT_EQ(again.joint_torques.size(), bike.joint_torques.size());
  for (size_t i = 0; i < again.joint_torques.size(); ++i)
    EXPECT_EQ(std::abs(again.joint_torques[i].value), 70.0) << again.joint_torques[i].name;
  EXPECT_EQ(again.initial.qdot, 6.5);
  EXPECT_EQ(again.initial.q, 0.25);
}

}  // namespace
}  // namespace rdyn::validate
