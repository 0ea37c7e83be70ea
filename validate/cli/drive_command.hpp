// `rdyn drive SCENE (--cadence-hz F | --profile FILE.csv) --out DIR`: the command around
// validate/analysis/drive (options checked before any work, outputs written atomically).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "models/scene.hpp"
#include "reduced/samples.hpp"
#include "validate/analysis/drive.hpp"

namespace rdyn::validate {

struct DriveArgs {
  std::string scene;
  std::optional<double> cadence_hz;  // constant rate [rev/s] of a revolute coordinate (sign: direction)
  std::string profile;               // or q(t) from a CSV: t,q_deg | t,q_m
  std::string model = "full";        // full | reduced
  std::optional<double> duration;    // default: one revolution (cadence), the profile's span
  std::optional<double> dt_out;      // default: the scene's output interval
  double grid_deg = 10.0;
  bool grid_given = false;  // else a default, refined where it does not resolve m1 (extract_resolving)
  std::string interpolation = "fourier";
  std::vector<std::string> sets;
  std::string motor;  // "STALL,NO_LOAD": check a torque–speed line against the drive (empty: none)
  std::string out;
  bool force = false;
};

int run_drive(const DriveArgs& args);

// What `rdyn drive` computes for a loaded scene, without writing it (the Python module's drive):
// the arguments checked as the CLI checks them (models::SceneError naming the option), the
// drive along the motion and run.json's content. `rows` are timeseries.csv's rows (every
// k-th statistics row and the last). args.scene, sets, out and force are not read; `table`, when
// given, is the reduced model's table (else extracted at args.grid_deg).
struct DriveRun {
  DriveRecord rows;
  nlohmann::json run;
  bool revolute = true;  // drive_Nm (else drive_N)
};
DriveRun drive_scene(const models::Scene& scene, const DriveArgs& args, const reduced::Samples* table = nullptr);
// The CSV's header names of a run's rows: drive_column_names (validate/analysis/drive.hpp).

}  // namespace rdyn::validate
