// Ranges of the numbers typed on rdyn's command line (README, "Limits"), one table for every
// subcommand. Each number is checked before any work starts, so nothing hangs or exhausts memory.
//
// Not the scene's table: models::limits (models/scene.hpp; docs/scene-format.md, "Limits") bounds
// what a scene may hold, and several names are the same with other values — a command-line grid
// may be finer (0.01° here, 0.05° in a scene: `extract` and `simulate` build one table from it,
// at most 36 000 points), and a typed cadence or power may be larger (1000 Hz and 1e7 W here, 20 Hz
// and 1e5 W in a scene). Options that replace a value of the scene itself take the scene's range:
// `rdyn optimize`'s --cadence-hz, --power-w and --grid-deg override its `optimize` block and are
// checked against models::limits (validate/cli/optimize_command.cpp, README). Always write these
// qualified (cli_limits::kMaxDuration_s), so the reader sees which table a bound comes from.
#pragma once

#include "models/scene.hpp"

namespace rdyn::validate::cli_limits {

inline constexpr double kMaxDuration_s = 1e5;
inline constexpr double kMinOutputInterval_s = 1e-6;
inline constexpr double kMaxOutputRows = 1e7;  // rows written, t = 0 included (~1.5 GB of CSV at most)
inline constexpr double kMinTolerance = 1e-14, kMaxTolerance = 1e-1;
inline constexpr double kMinFixedStep_s = 1e-7, kMaxFixedStep_s = 1.0;
inline constexpr double kMaxFixedSteps = 1e8;  // ~20 s of RK4 steps
inline constexpr double kMinGrid_deg = 0.01, kMaxGrid_deg = 90.0;  // 36000 grid points at most
inline constexpr int kMaxThreads = 256;
inline constexpr double kMaxCadence_Hz = 1000.0, kMaxPower_W = 1e7;
// drive --motor: the scene's own bounds for a motor (models::limits::kMaxForce, kMaxRate), so a
// line checked here can be written into a scene.
inline constexpr double kMaxMotorStall = models::limits::kMaxForce, kMaxMotorSpeed = models::limits::kMaxRate;

}  // namespace rdyn::validate::cli_limits
