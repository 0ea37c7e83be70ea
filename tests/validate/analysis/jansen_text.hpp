// The Jansen leg's scene text (tests/validate/scenes/jansen-leg.yaml) with and without the
// calibration grid it declares: the calibrate and sweep tests of a default grid that does not
// resolve the mechanism (10° misses its m1 by 10 %).
#pragma once

#include <fstream>
#include <sstream>
#include <string>

namespace rdyn::validate::test {

inline constexpr const char* kJansenCalibrationGrid = ", grid_deg: 2}";

inline std::string jansen_text() {
  std::ifstream in(RDYN_SOURCE_DIR "/tests/validate/scenes/jansen-leg.yaml");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The text without `grid_deg: 2` in its validation.calibrate block; empty when it has none.
inline std::string jansen_text_without_calibration_grid() {
  std::string yaml = jansen_text();
  const auto at = yaml.find(kJansenCalibrationGrid);
  if (at == std::string::npos) return "";
  return yaml.replace(at, std::string(kJansenCalibrationGrid).size(), "}");
}

}  // namespace rdyn::validate::test
