// `rdyn validate`: how close the reduced model comes to full forward dynamics, and at
// what computing cost, with the evidence behind each number.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/full_model.hpp"
#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "reduced/samples.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/harness/grid_check.hpp"
#include "validate/analysis/drive.hpp"
#include "validate/harness/compare.hpp"
#include "validate/harness/convergence.hpp"
#include "validate/io/progress.hpp"
#include "validate/harness/calibrated_run.hpp"
#include "validate/harness/run_record.hpp"
#include "validate/harness/time_scale.hpp"
#include "validate/harness/verdicts.hpp"

namespace rdyn::validate {

// Fewest output samples over which an error maximum is claimed (a 20-point maximum of a
// smooth signal sampled at 1/20 of its cycle still resolves its peak to ~1 %).
constexpr long kMinComparedSamples = 20;

struct ValidationOptions {
  bool quick = false;  // shorter ladders and single repeats (suites, smoke runs)
  std::vector<std::string> peers;  // peer engines to run beside the full model ("mujoco")
};

// One peer engine's ladder (validate/harness/peers.hpp): fixed-step runs with one integrator, and the
// reduced model's speedup over it at matched error.
struct PeerLadder {
  std::string engine, version, integrator;
  std::string how;  // how it was run, in plain words
  std::vector<RunRecord> runs;
  std::optional<double> speedup_at_matched_error;
  int matched_peer = -1, matched_reduced = -1;  // indices into runs and ValidationResult::runs
};

struct ValidationResult {
  std::string scene, scene_file, note, machine;
  std::vector<models::CompareValue> compare;  // published values the scene compares with
  double duration_s = 0.0, output_interval_s = 0.0;
  TimeScale time_scale;              // the scene's, from the reference
  std::vector<double> fixed_steps;   // rk4-fixed ladder derived from it [s]
  double reference_tolerance = 0.0;
  double reference_wall_s = 0.0;
  RunRecord reference_run;  // the reference's own stability metrics
  Comparison reference_change;  // reference at half its tolerance vs the reference
  SteadyWindow window;
  std::vector<RunRecord> runs;
  std::string full_timing;  // how the full-model ladder was timed (fair baseline), plain words
  std::vector<PeerLadder> peers;
  std::vector<double> peer_steps;  // peer ladders' fixed steps before fitting the output grid [s]
  std::vector<ExtractionRecord> extractions;
  double extraction_ms = 0.0;  // the 10° table
  ExtractionStages extraction_stages;  // the 10° table, median of each stage over the repeats
  double tightest_tolerance = 0.0;  // of the reduced rk8pd ladder
  std::string headline_quantity;  // the error that matches: first constraint force, else qdot
  std::vector<std::string> quantities;  // qdot, the constraint forces, the joint outputs, mean_qdot
  // Requested reactions the reduced model cannot give: name, why (compared on the full model alone).
  std::vector<std::pair<std::string, std::string>> reactions_not_given;
  std::vector<std::string> joint_output_quantities;  // the joint outputs among `quantities`
  double matched_target = 1e-3;
  std::optional<double> speedup_at_matched_error;
  int matched_full = -1, matched_reduced = -1;  // indices into runs
  int recommended = -1;                         // cheapest reduced run within the target (index)
  // Whether `recommended` is within the target on every judged quantity (else on the speed and
  // the headline quantity only, the others' misses shown in the verdicts).
  bool recommended_on_all = false;
  // The cheapest full run at equal or better error than the recommended run on the speed and
  // the headline quantity, and the recommended run's speedup over it: the first screen's one
  // speedup. When no ladder run is that accurate, the ladder's most accurate run (still less
  // accurate: recommended_full_as_accurate false), so the speedup is a floor, not the reference's
  // inflated ratio; −1 when the ladder has no completed full run (the reference stands in).
  int recommended_full = -1;
  bool recommended_full_as_accurate = true;
  std::optional<double> recommended_speedup;
  std::vector<Verdict> verdicts;
  std::vector<Baseline> baselines;              // the recommended run against full-model runs
  std::optional<ErrorBudget> budget;            // of the recommended run, headline quantity
  std::vector<ConvergenceSeries> convergence;   // headline quantity against the grid
  double convergence_floor = 0.0;               // 10× the reference's own change
  // The grid rdyn's commands take for this scene by default: 10°, halved while its table does not
  // resolve the mechanism (validate/analysis/build_reduced's extract_resolving). The ladder always
  // has it; the default thresholds, the figure's reduced run and the drive cycle are on it.
  double default_grid_deg = 10.0;
  GridCheck default_grid_check;      // its run against the run on half its grid (grid_check.hpp)
  reduced::Samples default_samples;  // that table (empty when it is the 10° one or none closed)
  models::TimeSeries reference, showcase;        // showcase: reduced, default grid, default settings
  int showcase_run = -1;
  reduced::Samples samples10;                    // the 10° table
  std::vector<std::vector<double>> dense_params; // q_deg, then m1, m2, me1.., me2.. at 1° (interpolant)
  std::vector<std::string> dense_names;
  std::optional<CalibrationResult> calibration;
  CalibrationOptions calibration_options;
  // The drive over one revolution at the scene's cadence (validation.calibrate) from both
  // models (calc_drive_cycle): scenes with a cadence whose coordinate turns fully.
  std::optional<DriveCycleComparison> drive_cycle;
  // Both models at the calibrated operating point over two revolutions (validate/harness/
  // calibrated_run.hpp): the calibration section's figure.
  std::optional<CalibratedRun> calibrated_run;
  std::vector<ThresholdResult> thresholds;
  bool default_thresholds = false;  // the scene declares none: judged on thresholds_of's defaults
  bool pass = true;
  std::vector<std::string> failures;  // why pass is false, in plain words

  // Marks the validation failed for `why`.
  void fail(std::string why) {
    pass = false;
    failures.push_back(std::move(why));
  }
  std::string failure_summary() const;
};

// The scene a reduced model is extracted from: with the internal constraint lines its joint
// outputs need (reduced/joint_outputs.hpp), when the scene asks for reactions or shaking.
models::Scene extraction_scene(const models::Scene& scene);

// Runs everything (engine + reduced) for one scene. Throws on scene/engine errors. The
// stages, in order: run_reference, plan_ladders (validate/harness/ladder_plan.hpp), the full and reduced
// ladders, analyse_runs, calibration, thresholds, calc_first_screen.
ValidationResult run_validation(const models::Scene& scene, const ValidationOptions& opt, Progress& progress);

// The table rdyn's commands take for the scene by default (ValidationResult::default_grid_deg):
// 10°, halved while it does not resolve the mechanism (extract_resolving); its samples are the
// drive cycle's. A sweep that does not close at any grid: 10° and no samples.
struct DefaultTable {
  double grid_deg = 10.0;
  reduced::Samples samples;
  GridCheck check;  // its run against the run on half its grid, as simulate checks it
};
DefaultTable calc_default_table(const models::Scene& scene);

// Stage 1: the reference (full model at the scene's reference tolerance), its change when the
// tolerance is halved, the compared window and the scene's time scale, into `v` (whose
// duration, output interval and reference tolerance are set).
void run_reference(const models::Scene& scene, engine::FullModel& full, ValidationResult& v, Progress& progress);

// A ladder run's timing (median of the repeats), stability metrics and errors against the
// reference; and a run that stopped, recorded with its reason and infinite cost and errors.
void finish_run(RunRecord& r, const std::vector<double>& walls, const models::TimeSeries& ts,
                const ValidationResult& v);
void mark_stopped(RunRecord& r, const std::string& why, const std::vector<std::string>& quantities);

// Stage 4 (no simulation): Pareto front, matched-error speedup, recommended setting and
// convergence series from v.runs.
void analyse_runs(ValidationResult& v);

// Stage 5b: the drive both models need to turn one revolution at the scene's cadence
// (validation.calibrate's cadence_Hz) with every load of the scene applied — `rdyn drive
// --cadence-hz F` of each model on 1° rows, the reduced model from the 10° table — into
// v.drive_cycle. Nothing when the scene declares no cadence, its coordinate is prismatic or does
// not turn fully (a range table), or the 10° table is missing.
void calc_drive_cycle(const models::Scene& scene, ValidationResult& v);

// Stage 7 (no simulation): verdicts, baselines and error budget at the recommended setting.
void calc_first_screen(ValidationResult& v);

}  // namespace rdyn::validate
