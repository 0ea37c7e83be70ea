// Scene reading: shipped scenes load; bad input gives SceneError naming file, line, field.
#include "models/scene_yaml.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rdyn::models {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string error_of(const std::string& yaml, std::vector<Override> o = {}) {
  try {
    parse_scene(yaml, "test.yaml", o);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

const char* kFourbar = R"(
name: fb
ground_points: {A: [0, 0], D: [0.3, 0]}
bodies:
  - {name: crank, mass_kg: 0.5, com_m: [0.04, 0], inertia_kgm2: 2.0e-4, points: {B: [0.08, 0]}}
  - {name: coupler, mass_kg: 1.2, com_m: [0.14, 0], inertia_kgm2: 7.8e-3, points: {C: [0.28, 0]}}
  - {name: rocker, mass_kg: 0.9, com_m: [0.1, 0], inertia_kgm2: 3.0e-3, points: {C: [0.2, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank}
  - {name: coupler, type: revolute, parent: crank, parent_point: B, child: coupler}
  - {name: rocker, type: revolute, parent: ground, parent_point: D, child: rocker, guess_deg: 90}
loops:
  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}
independent: crank
loads:
  - {type: resistance, name: bearing, body: crank, law: viscous, coefficient: 1.0e-3}
)";

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

TEST(SceneYaml, UnknownKeySuggestsNearestAndNamesLine) {
  std::string y = kFourbar;
  y.replace(y.find("mass_kg: 0.9"), 12, "mas_kg: 0.9");
  const std::string e = error_of(y);
  EXPECT_NE(e.find("test.yaml:7"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'mass_kg'"), std::string::npos) << e;
}

TEST(SceneYaml, OverridesReachScalarsByPathAndName) {
  const Scene s = parse_scene(kFourbar, "t.yaml", {parse_override("loads.bearing.coefficient=0.25"),
                                                   parse_override("bodies.1.mass_kg=2.5")});
  EXPECT_DOUBLE_EQ(s.resistances[0].coefficient, 0.25);
  EXPECT_DOUBLE_EQ(s.bodies[1].mass_kg, 2.5);
  const Scene b = load_scene("bicycle", {parse_override("bicycle_leg.hip_torque_Nm=50")});
  EXPECT_DOUBLE_EQ(b.joint_torques[0].value, 50.0);
  EXPECT_NE(error_of(kFourbar, {parse_override("loads.nosuch.coefficient=1")}).find("no list item"),
            std::string::npos);
  EXPECT_THROW(parse_override("novalue"), SceneError);
}

TEST(SceneYaml, BadValuesAreRefusedWithTheirField) {
  std::string y = kFourbar;
  y.replace(y.find("mass_kg: 0.9"), 12, "mass_kg: 0.0");
  // check_scene names the item by name; the reader finds its line (the rocker is on line 7).
  EXPECT_NE(error_of(y).find("test.yaml:7: field 'bodies.rocker.mass_kg'"), std::string::npos) << error_of(y);
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

TEST(SceneYaml, MalformedEmptyAndBinaryInputsAreRefused) {
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  EXPECT_NE(error_of("name: [unclosed\n").find("test.yaml"), std::string::npos);
  EXPECT_NE(error_of(std::string("\x01\x02\0\x7f", 4)).find("NUL"), std::string::npos);
  EXPECT_NE(error_of("just a string").find("mapping"), std::string::npos);
  EXPECT_NE(error_of(std::string(kFourbar).substr(0, 200)).find("test.yaml"), std::string::npos);
}

TEST(SceneYaml, MissingSceneFileIsNamed) {
  try {
    load_scene("/nonexistent/scene.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace rdyn::models
