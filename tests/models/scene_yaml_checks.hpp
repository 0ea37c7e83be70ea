// Shared by the scene-reading tests (scene_yaml_test, yaml_fields_test, scene_yaml_study_test):
// parse a scene text and check its refusal names file, field and line.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "models/scene_yaml.hpp"

namespace rdyn::models::test {

inline constexpr double kPi = 3.14159265358979323846;

inline std::string error_of(const std::string& yaml, std::vector<Override> o = {}) {
  try {
    parse_scene(yaml, "test.yaml", o);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

// The SceneError of parsing `yaml` (with overrides); fails the test when it parses.
inline SceneError refusal(const std::string& yaml, std::vector<Override> o = {}) {
  try {
    parse_scene(yaml, "test.yaml", o);
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "parsed:\n" << yaml;
  return SceneError("", 0, "", "");
}

// 1-based line of the first occurrence of `text` in `yaml`.
inline int line_in(const std::string& yaml, const std::string& text) {
  const auto at = yaml.find(text);
  EXPECT_NE(at, std::string::npos) << text;
  return 1 + static_cast<int>(std::count(yaml.begin(), yaml.begin() + static_cast<long>(at), '\n'));
}

// The refusal of `yaml` (with overrides `o`), checked: from test.yaml, naming `field`, with `says`
// in its message (empty: not checked) and, when `on_line` is given, on the line that holds it.
inline SceneError expect_refused(const std::string& yaml, const std::string& field, const std::string& says,
                          const std::string& on_line = "", std::vector<Override> o = {}) {
  const SceneError e = refusal(yaml, std::move(o));
  EXPECT_EQ(e.file(), "test.yaml") << field;
  EXPECT_EQ(e.field(), field) << e.what();
  if (!says.empty()) {
    EXPECT_NE(e.message().find(says), std::string::npos) << says << " | " << e.what();
  }
  if (!on_line.empty()) {
    EXPECT_EQ(e.line(), line_in(yaml, on_line)) << on_line << " | " << e.what();
  }
  return e;
}

// `yaml` with the first `from` replaced by `to`.
inline std::string with(std::string yaml, const std::string& from, const std::string& to) {
  const auto at = yaml.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? yaml : yaml.replace(at, from.size(), to);
}

inline const char* kFourbar = R"(
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

}  // namespace rdyn::models::test
