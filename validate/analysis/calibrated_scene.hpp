// Writing a calibrated scene (`rdyn calibrate --write-scene`): the scene's own YAML text with the
// calibrated load value, resistance and steady initial conditions, and a comment saying so.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {

// The scene's YAML rewritten with the calibrated load value (and, with a power, the
// resistance) and steady initial conditions (for --write-scene). Throws SceneError when the
// load's value is not a key of the text (a named load made by the bicycle_leg generator);
// check_writable tells before any work. `source`, `text` and `base` are how the scene was loaded
// (the text read once: a scene given as /dev/stdin cannot be read twice).
std::string calibrated_scene_yaml(const std::string& source, const std::string& text,
                                  const std::vector<models::Override>& base, const models::Scene& scene,
                                  const CalibrationOptions& opt, const CalibrationResult& r);

void check_writable(const std::string& text, const models::Scene& scene, const CalibrationOptions& opt);

}  // namespace rdyn::validate
