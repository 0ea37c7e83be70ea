// Population sweeps: many reduced-model cases in parallel threads, one CSV row per case
// (parameters, calibrated drive load, peak constraint force, speed fluctuation), shardable
// across machines (Slurm job arrays, GNU parallel): `--shard i/N` runs the i-th of N
// contiguous blocks of cases; each shard's CSV says which sweep and cases it holds, and
// merge_sweep_parts (sweep_part.hpp) joins them into what one process would have written.
#pragma once

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/sweep_part.hpp"
#include "validate/io/progress_meter.hpp"

namespace rdyn::validate {

// One axis of the sweep (read from `--vary` by validate/cli/sweep_axis.hpp).
struct SweepAxis {
  std::string key;  // a scene key path, as for --set
  std::vector<double> values;
};

struct SweepOptions {
  std::string scene;
  std::vector<std::string> sets;  // fixed overrides
  std::vector<SweepAxis> axes;
  double cadence_hz = 0.0;  // 0: the scene's validation.calibrate
  double power_w = 0.0;
  std::string load;         // empty: the scene's validation.calibrate.load, else every joint torque
  int shard = 0, shards = 1;
  int threads = 0;          // 0: hardware threads
  double grid_deg = 10.0;
  // false: the scene's validation.calibrate.grid_deg, else 10° halved per case while its table
  // does not resolve m1 (extract_resolving, validate/analysis/build_reduced.hpp).
  bool grid_given = false;
  // Non-zero: a drive sweep — each case is driven at this constant rate [rev/s] for one
  // revolution (reduced model, revolution_motion in drive.hpp) instead of calibrated, and its
  // row gives the drive's RMS, peak and mean, the mean and peak power and the peak constraint
  // force (what `rdyn drive --model reduced` reports). Excludes cadence_hz, power_w and load.
  double drive_cadence_hz = 0.0;
  // `--peak COLUMN` (repeatable): a peak_<COLUMN> column per name, after the others: the largest
  // |value| of that output column of the case's reduced run over its steady cycle (a drive
  // sweep: its revolution). validate/analysis/sweep_peaks.hpp.
  std::vector<std::string> peaks;
};

// A sweep checked and described before any case runs.
struct SweepPlan {
  SweepOptions opt;
  std::vector<models::Override> fixed;  // opt.sets, parsed
  CalibrationOptions calibration;       // the command line's, else the scene's validation.calibrate
  std::string force;                    // the first requested constraint force ("" none)
  SweepIdentity id;                     // the whole sweep: its fingerprint, scene hash and cases
  SweepRange range;                     // this shard's cases
  std::string header;                   // the CSV's column header (no line break)
  int result_fields = 0;                // fields between status and error (an error row leaves them empty)
  std::vector<bool> changes_mechanism;  // per axis: its two ends need two tables (run first)
};

// Loads the base scene and checks everything before work: every axis key is applied at both
// ends of its range to the base scene, so an unknown key or an out-of-range value is a
// SceneError here; the scene must be calibratable (a drive sweep: revolute, the rate finite);
// at most 1e6 cases; every --peak column one of the base scene's reduced run (check_peak_columns).
SweepPlan plan_sweep(const SweepOptions& opt);

struct SweepResult {
  std::string csv;         // sweep_csv: metadata line, header, this shard's rows
  long cases = 0;          // in this shard
  long failed = 0;         // rows with status "error"
  int threads = 0;         // worker threads used
  long tables = 0;         // reduced tables extracted (a thread reuses its last one)
  long walks = 0;          // of those, the ones whose dead-point walk ran (the others continued from a neighbour)
  double elapsed_s = 0.0;  // wall time of the cases
};

// Runs the cases of the plan's shard, reporting each done case to `progress` (may be null). A
// failing case gives a row with status "error" and its message (RFC 4180-quoted), and does not
// stop the others. The cases run with the axes that change the mechanism varying slowest (so a
// thread's next case mostly reuses its table); the rows are in case order.
SweepResult run_sweep(const SweepPlan& plan, StderrProgress* progress);

// plan_sweep then run_sweep without progress.
SweepResult run_sweep(const SweepOptions& opt);

// The scene overrides of case `index` (the fixed ones, then one per axis, the last axis varying
// fastest) and the varied values as the row writes them (",v1,v2…").
struct SweepCase {
  std::vector<models::Override> overrides;
  std::string params;
};
SweepCase sweep_case(const SweepPlan& plan, long index);

// One case's CSV row (no line break), computed alone (no table reuse): what run_sweep writes
// for it. A failing case gives its "error" row. The Python module maps this over a pool.
std::string run_sweep_case(const SweepPlan& plan, long index);

}  // namespace rdyn::validate
