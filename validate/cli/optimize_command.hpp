// `rdyn optimize SCENE --out DIR`: the command around validate/analysis/optimize (options checked, outputs
// written atomically through validate/io/output_dir, exit 1 without output when a target is missed).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/analysis/optimize.hpp"

namespace rdyn::validate {

struct OptimizeArgs {
  std::string scene;
  std::vector<std::string> sets;
  double cadence_hz = 1.0, power_w = 0.0;
  bool cadence_given = false, power_given = false;
  // Unset: the scene's block decides; any typed value is checked (0 and NaN refused).
  std::optional<int> harmonics;
  std::string objective;
  std::optional<double> p, max_load;
  std::string force_name;
  bool force_name_given = false;  // typed, even empty (refused)
  std::vector<std::string> add_torques;
  double add_torque_max = 50.0;
  int max_evaluations = 400;
  double rel_tolerance = 1e-4;
  double grid_deg = 10.0;
  bool grid_given = false;  // else the scene's validation.calibrate.grid_deg (default 10)
  std::string interpolation = "fourier";
  double full_duration_s = 20.0;
  std::string out;
  bool force = false;
};

// The options of a run from the arguments and the scene (its optimize and validation.calibrate
// blocks), every number checked first: throws models::SceneError naming the option or field.
OptimizeOptions optimize_options_of(const models::Scene& scene, const OptimizeArgs& args);

int run_optimize(const OptimizeArgs& args);

}  // namespace rdyn::validate
