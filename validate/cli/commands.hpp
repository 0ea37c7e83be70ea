// The rdyn subcommands. Each returns the process exit status; errors are thrown and
// mapped to statuses by main (2 for bad input).
#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/sweep.hpp"
#include "validate/io/argument_error.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {

// The --set K=V overrides parsed (SceneError naming the malformed one), and the scene loaded
// with them: what every subcommand does first (commands.cpp, validate_command.cpp).
std::vector<models::Override> overrides_of(const std::vector<std::string>& sets);
models::Scene load(const std::string& scene, const std::vector<std::string>& sets);

struct SimulateArgs {
  std::string scene;
  std::string model = "full";  // full | reduced
  std::optional<double> duration;   // empty: the scene's
  std::optional<double> dt_out;
  std::optional<double> tolerance;  // full-model integrator accuracy
  std::string integrator = "rkmerson";
  std::string route = "actuator";
  std::vector<std::string> sets;
  std::string out;
  bool force = false;  // write into a folder that holds files rdyn did not write
  // reduced model
  std::string table;  // CSV from `rdyn extract`; empty: extract now
  double grid_deg = 10.0;
  // Not given: a periodic table whose m1 the grid does not resolve (reduced::calc_half_grid_miss
  // above kAutoRefineMiss) is extracted again at half the step, down to kMinAutoGrid_deg.
  bool grid_given = false;
  std::string method = "kinetostatic";
  std::string interpolation = "fourier";  // measured more accurate than cubic (docs/theory.md)
  bool energy_consistent = false;
  std::string reduced_integrator = "rk8pd";
  double reduced_tolerance = 1e-8;  // measured: integration error ≪ interpolation error at 10° (docs/theory.md)
  double fixed_step = 1e-3;
};
int run_simulate(const SimulateArgs& args);
// A periodic table whose m1 its grid does not resolve: run.json's `table_m1_half_grid_miss`, and
// above reduced::kCoarseTableMiss a warning on standard error (simulate and drive).
void warn_coarse_table(const reduced::Samples& s, nlohmann::json& run);
// What `rdyn simulate` computes, without writing it (the Python module's simulate): the
// arguments checked as the CLI checks them (ArgumentError names the option), the run, and
// run.json's content. args.scene, sets, out and force are not read.
struct SimulateRun {
  models::TimeSeries ts;  // timeseries.csv's columns
  nlohmann::json run;     // run.json
};
void check_simulate_args(const models::Scene& scene, const SimulateArgs& args);
// `table`, when given, stands for args.table (a table already read or extracted).
SimulateRun simulate_scene(const models::Scene& scene, const SimulateArgs& args,
                           const reduced::Samples* table = nullptr);

struct ExtractArgs {
  std::string scene;
  double grid_deg = 10.0;
  std::string method = "kinetostatic";
  std::vector<std::string> sets;
  std::string out;  // FILE.csv
  bool force = false;  // replace a file rdyn did not write
};
int run_extract(const ExtractArgs& args);
// What `rdyn extract` computes for a loaded scene (the grid and method checked as the CLI
// checks them; `reactions: all` resolved as simulate resolves it).
Extraction extract_scene(const models::Scene& scene, double grid_deg, const std::string& method);
// Recognises a table rdyn wrote, so saving over it needs no --force.
bool is_rdyn_table_file(const std::string& first_bytes);

struct CalibrateArgs {
  std::string scene;
  // Given on the command line, else the scene's validation.calibrate, else 1 Hz / no power
  // (mean-speed mode: the resistances stay as given).
  double cadence_hz = 1.0;
  double power_w = 0.0;
  bool cadence_given = false, power_given = false;
  std::string load;  // --load: a joint_torque or motor; empty: validation.calibrate.load, else every joint torque
  std::vector<std::string> sets;
  std::string write_scene;  // optional output YAML
  bool force = false;
  double grid_deg = 10.0;
  bool grid_given = false;  // else the scene's validation.calibrate.grid_deg (default 10)
  std::string interpolation = "fourier";
};
int run_calibrate(const CalibrateArgs& args);
// The options `rdyn calibrate` runs with for these arguments (checked; ArgumentError), and the
// JSON it prints for a result (without "written_scene").
CalibrationOptions check_calibrate_args(const models::Scene& scene, const CalibrateArgs& args);
nlohmann::json calibration_json(const models::Scene& scene, const CalibrationOptions& opt,
                                const CalibrationResult& result);

struct ValidateArgs {
  std::string scene;  // or suite
  std::string suite;  // folder of scenes
  std::string out;
  std::vector<std::string> sets;
  bool quick = false;     // short ladders (default for --suite)
  bool thorough = false;  // full ladders even for --suite
  bool force = false;
  std::vector<std::string> peers;  // peer engines beside the full model (validate/harness/peers.hpp)
};
int run_validate(const ValidateArgs& args);
// What `rdyn validate SCENE --out DIR` does for a loaded scene (the Python module's validate):
// the peers checked, the validation run, its report written into args.out (atomically; args.force
// as --force) and summary.json's content returned ("status": "pass" or "fail", the CLI's exit 0
// or 1). args.scene, suite and sets are not read. `progress` reports the stages.
nlohmann::json validate_scene(const models::Scene& scene, const ValidateArgs& args, Progress& progress);

// Re-renders a report from a summary.json written by `rdyn validate`.
struct ReportArgs {
  std::string summary;  // path of summary.json
  std::string out;      // output folder
  bool force = false;
};
int run_report(const ReportArgs& args);

struct SweepArgs {
  std::vector<std::string> inputs;  // the scene; with --merge, the part CSVs
  std::vector<std::string> vary;
  std::vector<std::string> sets;
  std::string out;
  std::string shard = "0/1";
  std::optional<int> threads;                  // none: the hardware's threads
  std::optional<double> cadence_hz, power_w;   // none: the scene's validation.calibrate
  std::string load;  // --load, as for calibrate
  std::optional<double> drive_cadence_hz;      // a drive sweep at this rate [rev/s] (no calibration)
  double grid_deg = 10.0;
  bool grid_given = false;  // else the scene's validation.calibrate.grid_deg, else 10 (refined)
  std::vector<std::string> peaks;  // --peak COLUMN (repeatable): a peak_<COLUMN> column each
  bool force = false;
  bool resume = false;  // skip when --out already holds this shard complete
  std::string merge;    // OUT.csv of `--merge OUT.csv PART...` ("" runs a sweep)
};
int run_sweep_command(const SweepArgs& args);
// The sweep's options from the command line's, every number checked as `rdyn sweep` checks it
// (ArgumentError names the option; an axis text a SceneError); out, force, resume, merge not read.
SweepOptions check_sweep_args(const SweepArgs& args);

// `rdyn export-mjcf`: the scene as MJCF (MuJoCo XML), its loops closed at the assembled initial
// configuration (models/mjcf_export.hpp).
struct ExportMjcfArgs {
  std::string scene;
  std::vector<std::string> sets;
  std::string out = "/dev/stdout";
  bool force = false;
  bool fold = false;             // fold geared bodies into their drivers
  double timestep_s = 1e-3;      // <option timestep>
  std::string integrator = "Euler";
};
int run_export_mjcf(const ExportMjcfArgs& args);

// The scene whose joint outputs a reduced run gives: with `reactions: all`, the reactions the
// reduced model can give, each other one named in a warning and in run["reactions_not_given"]
// (reduced::split_reduced_reactions); otherwise the scene (a listed reaction it cannot give is
// refused when the model is built). simulate and drive.
models::Scene reduced_output_scene(const models::Scene& scene, nlohmann::json& run);

}  // namespace rdyn::validate
