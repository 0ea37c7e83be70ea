// Plain records of one validation run: what was run, what it cost, how far it landed from the
// reference. Every stage of `rdyn validate` reads and writes these; none holds a model.
#pragma once

#include <string>

#include "models/scene.hpp"
#include "validate/harness/compare.hpp"

namespace rdyn::validate {

struct RunRecord {
  std::string model;  // "full", "reduced" or a peer engine ("mujoco")
  double tolerance = 0.0;
  std::string integrator;
  double grid_deg = 0.0;      // reduced
  std::string interpolation;  // reduced: as requested
  std::string fit;            // reduced: the interpolant built (a range table: "cubic (not-a-knot)" for fourier/cubic)
  bool energy_consistent = false;
  double fixed_step_s = 0.0;     // rk4-fixed, and a peer's fixed step
  double wall_s = 0.0;           // median over repeats, the run as simulated [s]
  double per_simulated_s = 0.0;  // wall_s / duration [s per simulated s]
  int repeats = 0;
  // Full model (fair baseline): the timed repeats write outputs this far apart (the whole run), so
  // the output grid never caps Simbody's step; errors and the statistics below come from one more
  // run of the same settings on the output grid. 0: timed on the output grid.
  double timed_output_interval_s = 0.0;
  long timed_steps = 0;  // steps of the timed run
  long steps = 0;
  long rejected = 0;  // rejected steps (error control)
  double smallest_step_s = 0.0;
  double constraint_violation_m = 0.0;    // full model: largest loop gap seen
  long events = 0;                        // load switches
  double energy_residual_rel = 0.0;       // max|E − E0 − W| / max|E|
  double cycles = 0.0;                    // revolutions of the independent coordinate in the run
  double energy_drift_per_cycle_J = 0.0;  // |E − E0 − W| at the end / cycles
  Comparison errors;  // reduced: its rows by single steps from the step starts (step_outputs)
  // Reduced adaptive and fixed-step runs: the timed run's quintic-Hermite rows against those
  // rows (relative to their peak): what output interpolation between steps adds; empty for
  // full runs.
  Comparison output_interpolation;
  double compared_run_wall_s = 0.0;  // reduced: wall time of the (untimed) run with step_outputs [s]
  bool pareto = false;
  std::string failure;  // why the run stopped (empty when it completed)
  std::string label() const;
  // Max error of `quantity` relative to its peak; +∞ when the run has none (stopped runs).
  double error_of(const std::string& quantity) const;
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

}  // namespace rdyn::validate
