// Calibration: the resistance dissipates P watts at cadence F; find the constant drive
// torque that holds the mean steady cadence at F — with the reduced model, confirmed with the
// full model (GSL Brent instead of iterating by hand).
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/scene_yaml.hpp"
#include "validate/progress.hpp"

namespace rdyn::validate {

struct CalibrationOptions {
  double cadence_hz = 1.0;
  double power_w = 125.0;
  double grid_deg = 10.0;
  std::string interpolation = "fourier";
  double tolerance = 1e-10;    // reduced integrator
  double full_check_s = 6.0;   // full-model confirmation run, from the steady cycle (0: skip)
};

struct CalibrationResult {
  double torque_Nm = 0.0;               // drive torque magnitude (each gated/ungated joint torque)
  double initial_guess_Nm = 0.0;        // from the energy balance per revolution
  double resistance_coefficient = 0.0;  // c0, c1 or c2 of the scene's resistance
  double mean_cadence_hz_reduced = 0.0;
  double mean_cadence_hz_full = 0.0;     // NaN when the full-model check was skipped
  double mean_power_w = 0.0;            // mean power of the drive = dissipated power (steady)
  std::string force_name;               // first requested constraint force (empty if none)
  double peak_force_N = 0.0;            // max |F| over the steady cycle (reduced)
  double peak_force_full_N = 0.0;
  double speed_fluctuation = 0.0;       // (max − min)/mean of q̇ over the steady cycle (reduced)
  double speed_fluctuation_full = 0.0;
  double drive_work_per_rev_per_Nm = 0.0;  // Σ ∫ r_j·gate dq: the gated joints' swing [rad]
  double steady_q = 0.0, steady_qdot = 0.0;  // a point of the steady cycle (initial conditions)
  int evaluations = 0;                  // steady cycles computed
  double wall_time_s = 0.0;
};

// Checks that `scene` can be calibrated at all (a drive torque to scale, exactly one resistance
// turning at a fixed ratio to q, positive cadence and power) and that it assembles; throws
// models::SceneError / engine::EngineError (bad input) otherwise. Cheap: sweeps call it on the
// base scene before any case runs.
void check_calibratable(const models::Scene& scene, const CalibrationOptions& opt);

// Throws as check_calibratable, and models::NumericalError when no torque reaches F or the
// result misses its target.
CalibrationResult calibrate(const models::Scene& scene, const CalibrationOptions& opt, Progress& progress);

// The scene's YAML rewritten with the calibrated torque, resistance and steady initial
// conditions (for --write-scene). `source`, `text` and `base` are how the scene was loaded
// (the text read once: a scene given as /dev/stdin cannot be read twice).
std::string calibrated_scene_yaml(const std::string& source, const std::string& text,
                                  const std::vector<models::Override>& base, const models::Scene& scene,
                                  const CalibrationOptions& opt, const CalibrationResult& r);

}  // namespace rdyn::validate
