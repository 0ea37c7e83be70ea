// `rdyn validate`: how close the reduced model comes to full forward dynamics, and at
// what computing cost, with the evidence behind each number.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "reduced/samples.hpp"
#include "validate/calibrate.hpp"
#include "validate/compare.hpp"
#include "validate/progress.hpp"

namespace rdyn::validate {

struct RunRecord {
  std::string model;  // "full" or "reduced"
  double tolerance = 0.0;
  std::string integrator;
  double grid_deg = 0.0;        // reduced
  std::string interpolation;    // reduced
  bool energy_consistent = false;
  double fixed_step_s = 0.0;    // rk4-fixed
  double wall_s = 0.0;          // median over repeats, whole run
  double per_simulated_s = 0.0; // wall_s / duration [s per simulated s]
  int repeats = 0;
  long steps = 0;
  long rejected = 0;                 // rejected steps (error control)
  double smallest_step_s = 0.0;
  double constraint_violation_m = 0.0;  // full model: largest loop gap seen
  long events = 0;                   // load switches
  double energy_residual_rel = 0.0;  // max|E − E0 − W| / max|E|
  double cycles = 0.0;                // revolutions of the independent coordinate in the run
  double energy_drift_per_cycle_J = 0.0;  // |E − E0 − W| at the end / cycles
  Comparison errors;
  bool pareto = false;
  std::string failure;  // why the run stopped (empty when it completed)
  std::string label() const;
};

struct ExtractionRecord {
  double grid_deg = 0.0;
  double ms = 0.0;  // median wall time of the extraction [ms]
  long calls = 0;   // kinetostatic calls
  int points = 0;
};

struct ThresholdResult {
  models::Threshold threshold;
  double error = 0.0;
  bool pass = false;
  std::string run;
};

struct ValidationOptions {
  bool quick = false;  // shorter ladders and single repeats (suites, smoke runs)
};

struct ValidationResult {
  std::string scene, scene_file, note, machine;
  double duration_s = 0.0, output_interval_s = 0.0;
  double reference_tolerance = 0.0;
  double reference_wall_s = 0.0;
  RunRecord reference_run;  // the reference's own stability metrics
  Comparison reference_change;  // reference at half its tolerance vs the reference
  SteadyWindow window;
  std::vector<RunRecord> runs;
  std::vector<ExtractionRecord> extractions;
  double extraction_ms = 0.0;  // the 10° table (the paper's grid)
  std::string headline_quantity;  // the error that matches: first constraint force, else qdot
  double matched_target = 1e-3;
  std::optional<double> speedup_at_matched_error;
  int matched_full = -1, matched_reduced = -1;  // indices into runs
  models::TimeSeries reference, showcase;        // showcase: reduced, 10°, default settings
  int showcase_run = -1;
  reduced::Samples samples10;                    // the 10° table
  std::vector<std::vector<double>> dense_params; // q_deg, then m1, m2, me1.., me2.. at 1° (interpolant)
  std::vector<std::string> dense_names;
  std::optional<CalibrationResult> calibration;
  CalibrationOptions calibration_options;
  std::vector<ThresholdResult> thresholds;
  bool pass = true;
  std::vector<std::string> failures;  // why pass is false, in plain words

  // Marks the validation failed for `why`.
  void fail(std::string why) {
    pass = false;
    failures.push_back(std::move(why));
  }
  std::string failure_summary() const;
};

// Runs everything (engine + reduced) for one scene. Throws on scene/engine errors.
ValidationResult run_validation(const models::Scene& scene, const ValidationOptions& opt, Progress& progress);

}  // namespace rdyn::validate
