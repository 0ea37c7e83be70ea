// Population sweeps: many reduced-model cases in parallel threads, one CSV row per case
// (parameters, calibrated drive load, peak constraint force, speed fluctuation), shardable
// across machines (Slurm job arrays, GNU parallel): `--shard i/N` runs the i-th of N
// contiguous blocks of cases, and the shards' CSVs concatenate (only shard 0 writes the header).
#pragma once

#include <string>
#include <vector>

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
};

struct SweepResult {
  std::string csv;  // header only on shard 0
  long cases = 0;   // in this shard
  long failed = 0;  // rows with status "error"
};

// Runs the cases of this shard. Every axis key is first applied at both ends of its range to
// the base scene, so an unknown key or an out-of-range value is a SceneError before any work.
// A failing case gives a row with status "error" and its message (RFC 4180-quoted), and
// does not stop the others.
SweepResult run_sweep(const SweepOptions& opt, bool show_progress);

}  // namespace rdyn::validate
