// The study sections of a scene (models/scene_yaml_study.cpp): outputs (reactions: all or
// names), validation's calibrate block, optimize's block with its refusals.
#include "models/scene_yaml_study.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "models/scene_hash.hpp"
#include "models/scene_write.hpp"
#include "scene_yaml_checks.hpp"

namespace rdyn::models {
namespace {

using namespace test;

// validation.calibrate: power_W is optional (mean-speed mode), load names the drive load.
TEST(SceneYamlStudy, CalibrateBlockNamesItsLoadAndMayOmitThePower) {
  const Scene b = load_scene("bicycle");
  EXPECT_EQ(b.validation.calibrate_power_W, 125.0);
  EXPECT_EQ(b.validation.calibrate_load, "");
  const Scene s = load_scene(
      "slider-crank", {parse_override("validation.calibrate.cadence_Hz=3"), parse_override("validation.calibrate.load=motor")});
  EXPECT_EQ(s.validation.calibrate_cadence_Hz, 3.0);
  EXPECT_EQ(s.validation.calibrate_power_W, 0.0);
  EXPECT_EQ(s.validation.calibrate_load, "motor");
  EXPECT_EQ(s.validation.calibrate_grid_deg, 10.0);  // the default
}

// validation.calibrate.grid_deg: the calibration table's grid (a geared mechanism needs a finer
// one), checked like a threshold's grid and written back only when not the default.
TEST(SceneYamlStudy, CalibrateGridIsReadCheckedAndWritten) {
  const Scene five = load_scene("bicycle", {parse_override("validation.calibrate.grid_deg=5")});
  EXPECT_EQ(five.validation.calibrate_grid_deg, 5.0);
  EXPECT_NE(scene_to_yaml(five).find("    grid_deg: 5\n"), std::string::npos);
  EXPECT_EQ(scene_to_yaml(load_scene("bicycle")).find("grid_deg: 10\n    "), std::string::npos);
  const std::string yaml = read_scene_text("bicycle");
  EXPECT_NE(error_of(yaml, {{"validation.calibrate.grid_deg", "7"}}).find("7° does not divide 360°"), std::string::npos);
  EXPECT_NE(error_of(yaml, {{"validation.calibrate.grid_deg", "0"}}).find("validation.calibrate.grid_deg"),
            std::string::npos);
}

TEST(SceneYamlStudy, JointOutputsAllOrNames) {
  const auto all = load_scene("fourbar", {{"outputs.joints", "all"}, {"outputs.reactions", "all"},
                                          {"outputs.shaking", "true"}});
  EXPECT_EQ(all.outputs.joints, (std::vector<std::string>{"crank", "coupler", "rocker"}));
  EXPECT_EQ(all.outputs.reactions, (std::vector<std::string>{"crank", "coupler", "rocker", "C"}));  // joints, loops
  EXPECT_TRUE(all.outputs.shaking);
  const std::string yaml = read_scene_text("fourbar") + "\n";
  const auto listed = parse_scene(
      std::string(yaml).replace(yaml.find("outputs:\n"), 9, "outputs:\n  joints: [rocker]\n  reactions: [C, crank]\n"),
      "t.yaml");
  EXPECT_EQ(listed.outputs.joints, (std::vector<std::string>{"rocker"}));
  EXPECT_EQ(listed.outputs.reactions, (std::vector<std::string>{"C", "crank"}));
  const std::string bad = std::string(yaml).replace(yaml.find("outputs:\n"), 9, "outputs:\n  reactions: [crank, D]\n");
  const auto e = refusal(bad);
  EXPECT_EQ(e.field(), "outputs.reactions");
  EXPECT_NE(e.message().find("unknown joint or loop 'D'"), std::string::npos) << e.what();
  EXPECT_GT(e.line(), 0);
  EXPECT_NE(error_of(yaml, {{"outputs.joints", "some"}}).find("expected all or a list of joint names"),
            std::string::npos);
}

// The optimize block (rdyn optimize): read as written, and every bad field refused with its
// line and dotted path.
TEST(SceneYamlStudy, OptimizeBlockReadsAndRefusesBadFields) {
  std::ifstream in(std::string(RDYN_SCENES) + "/bicycle.yaml");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string y = ss.str();
  const Scene s = parse_scene(y, "bicycle.yaml");
  ASSERT_TRUE(s.optimize);
  ASSERT_EQ(s.optimize->loads.size(), 2u);
  EXPECT_EQ(s.optimize->loads[1].load, "hip_torque_l");
  EXPECT_EQ(s.optimize->loads[1].same_as, "hip_torque_r");
  EXPECT_NEAR(s.optimize->loads[1].shift_rad, kPi, 1e-15);
  EXPECT_EQ(s.optimize->force, "knee");
  EXPECT_EQ(s.optimize->harmonics, 3);
  EXPECT_EQ(s.optimize->max_load, 250.0);
  EXPECT_TRUE(s.optimize->nonnegative);
  EXPECT_EQ(s.optimize->objective, "peak");
  // The block is not part of the mechanism: the scene hash ignores it.
  const std::string without = y.substr(0, y.find("optimize:"));
  EXPECT_EQ(scene_hash(parse_scene(without, "b.yaml")), scene_hash(s));
  EXPECT_FALSE(parse_scene(without, "b.yaml").optimize);

  struct Case {
    std::string from, to, field, says;
  };
  const std::vector<Case> cases{
      {"same_as: hip_torque_r,", "same_as: hip_torque_l,", "optimize.loads[1].same_as", "its own shape"},
      {"{load: hip_torque_r}", "{load: hip_torque_r, same_as: hip_torque_l}", "optimize.loads[0].same_as",
       "takes its shape from"},
      {"- {load: hip_torque_r}\n", "", "optimize.loads[0].same_as", "not a design load listed"},
      {"shift_deg: 180", "shift_deg: .nan", "optimize.loads[1].shift_deg", "finite"},
      {"shift_deg: 180", "shift_deg: 400", "optimize.loads[1].shift_deg", "360"},
      {"{load: hip_torque_r}", "{load: hip_torque_r, shift_deg: 10}", "optimize.loads[0].shift_deg", "needs same_as"},
      {"harmonics: 3", "harmonics: 13", "optimize.harmonics", "[1, 12]"},
      {"harmonics: 3", "harmonics: 0", "optimize.harmonics", "[1, 12]"},
      {"harmonics: 3", "harmonics: 2.5", "optimize.harmonics", "whole number"},
      {"max_load: 250", "max_load: -1", "optimize.max_load", "must be in"},
      {"max_load: 250", "max_load: 1e9", "optimize.max_load", "must be in"},
      {"force: knee", "force: ankle", "optimize.force", "no requested constraint force"},
      {"objective: peak", "objective: mean", "optimize.objective", "peak or pnorm"},
      {"objective: peak", "objective: peak\n  p: 4", "optimize.p", "pnorm"},
      {"objective: peak", "objective: pnorm\n  p: 1", "optimize.p", "[2, 64]"},
      {"nonnegative: true", "nonnegative: maybe", "optimize.nonnegative", "true or false"},
      {"objective: peak", "objective: peak\n  of: pedal_r", "optimize.of", "unknown joint"},
      {"objective: peak", "objective: peak\n  sharpness: 3", "optimize.sharpness", "unknown key"},
  };
  for (const auto& c : cases) {
    const std::string bad = with(y, c.from, c.to);
    EXPECT_GT(expect_refused(bad, c.field, c.says).line(), line_in(bad, "optimize:") - 1) << c.to;
  }
  // A design load the scene does not make is `rdyn optimize`'s refusal (validate/analysis/optimize.cpp),
  // not the reader's: with the drive off ("no drive") the generator makes no hip torques.
  const Scene off = parse_scene(y, "b.yaml", {parse_override("bicycle_leg.hip_torque_Nm=0")});
  EXPECT_TRUE(std::none_of(off.joint_torques.begin(), off.joint_torques.end(),
                          [](const JointTorque& t) { return t.name == "hip_torque_r"; }));
  EXPECT_EQ(off.line_of("optimize.loads[0].load"), line_in(y, "{load: hip_torque_r}"));
  EXPECT_NO_THROW(parse_scene(with(y, "{load: hip_torque_l,", "{load: hip_torque_x,"), "b.yaml"));
  // pnorm with its exponent parses.
  const Scene p = parse_scene(with(y, "objective: peak", "objective: pnorm\n  p: 12"), "b.yaml");
  EXPECT_EQ(p.optimize->objective, "pnorm");
  EXPECT_EQ(p.optimize->p, 12.0);
}

}  // namespace
}  // namespace rdyn::models
