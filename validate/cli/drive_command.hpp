// `rdyn drive SCENE (--cadence-hz F | --profile FILE.csv) --out DIR`: the command around
// validate/analysis/drive (options checked before any work, outputs written atomically).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace rdyn::validate {

struct DriveArgs {
  std::string scene;
  std::optional<double> cadence_hz;  // constant rate [rev/s] of a revolute coordinate (sign: direction)
  std::string profile;               // or q(t) from a CSV: t,q_deg | t,q_m
  std::string model = "full";        // full | reduced
  std::optional<double> duration;    // default: one revolution (cadence), the profile's span
  std::optional<double> dt_out;      // default: the scene's output interval
  double grid_deg = 10.0;
  std::string interpolation = "fourier";
  std::vector<std::string> sets;
  std::string motor;  // "STALL,NO_LOAD": check a torque–speed line against the drive (empty: none)
  std::string out;
  bool force = false;
};

int run_drive(const DriveArgs& args);

}  // namespace rdyn::validate
