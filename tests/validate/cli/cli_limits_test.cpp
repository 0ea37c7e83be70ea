// The command line's bounds (validate/cli/cli_limits.hpp) against the library's where the
// library checks the same option: a CLI bound looser than the library's would let a typed value
// through to a library error that does not name the option (or to the wrong exit status). Each
// bound is checked by the library's own check at the CLI's edge, not by comparing constants.
#include "validate/cli/cli_limits.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/forward_dynamics.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/adaptive_integrator.hpp"
#include "reduced/extract.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/cli/commands.hpp"
#include "validate/io/argument_error.hpp"

namespace rdyn::validate {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Whether the reduced simulation accepts these options (its own check, TableError otherwise).
bool reduced_accepts(const reduced::ReducedOptions& o) {
  try {
    reduced::check_reduced_options(o);
    return true;
  } catch (const reduced::TableError&) {
    return false;
  }
}

bool cli_accepts(const models::Scene& scene, const SimulateArgs& a) {
  try {
    check_simulate_args(scene, a);
    return true;
  } catch (const ArgumentError&) {
    return false;
  }
}

// --tolerance / --reduced-tolerance: the reduced integrator takes every tolerance the CLI does,
// and the edges themselves; the full model's (0, 1] contains them too.
TEST(CliLimits, TolerancesAtTheCliEdgesAreAcceptedByTheReducedIntegrator) {
  for (double tol : {cli_limits::kMinTolerance, cli_limits::kMaxTolerance}) {
    reduced::ReducedOptions o;
    o.tolerance = tol;
    EXPECT_TRUE(reduced_accepts(o)) << tol;
    EXPECT_GT(tol, 0.0);
    EXPECT_LE(tol, 1.0);  // engine/forward_dynamics.cpp check_options: (0, 1]
  }
  // The scene's own tolerance has the same range: `--tolerance` replaces simulation.tolerance.
  EXPECT_LE(models::limits::kMinTolerance, cli_limits::kMinTolerance);
  EXPECT_GE(models::limits::kMaxTolerance, cli_limits::kMaxTolerance);
  // And the check can fail: just outside the CLI's range the library refuses as well.
  reduced::ReducedOptions o;
  o.tolerance = cli_limits::kMaxTolerance * 1.01;
  EXPECT_FALSE(reduced_accepts(o));
}

// --fixed-step (simulate) and --timestep: rk4-fixed takes the CLI's edges.
TEST(CliLimits, FixedStepsAtTheCliEdgesAreAcceptedByRk4Fixed) {
  for (double h : {cli_limits::kMinFixedStep_s, cli_limits::kMaxFixedStep_s}) {
    reduced::ReducedOptions o;
    o.integrator = "rk4-fixed";
    o.fixed_step_s = h;
    o.duration_s = 1.0;
    o.output_interval_s = 0.01;
    EXPECT_TRUE(reduced_accepts(o)) << h;
  }
  // The step budget the CLI allows (duration / step ≤ kMaxFixedSteps) fits the library's default.
  EXPECT_LE(cli_limits::kMaxFixedSteps, static_cast<double>(reduced::kDefaultMaxSteps));
}

// --duration / --dt-out: every pair the CLI accepts gives a row count both simulations accept,
// in particular at the CLI's row limit (the library counts rows including t = 0).
TEST(CliLimits, TheCliRowLimitIsWithinTheSimulationsRowLimit) {
  const models::Scene scene = models::load_scene("fourbar");
  int accepted = 0;
  for (double duration : {10.0, 100.0, 7.3}) {
    for (double dt_out : {duration / cli_limits::kMaxOutputRows, duration / (cli_limits::kMaxOutputRows - 1),
                          duration / (cli_limits::kMaxOutputRows - 2)}) {
      SimulateArgs a;
      a.duration = duration;
      a.dt_out = dt_out;
      if (!cli_accepts(scene, a)) continue;
      ++accepted;
      reduced::ReducedOptions o;
      o.duration_s = duration;
      o.output_interval_s = dt_out;
      EXPECT_TRUE(reduced_accepts(o)) << "the CLI accepts " << duration << " s at " << dt_out
                                      << " s, the reduced simulation refuses";
      // The full model's limit: duration / interval + 1 rows (engine/forward_dynamics.cpp).
      EXPECT_LE(duration / dt_out + 1, static_cast<double>(engine::kMaxOutputRows) * (1 + 1e-12))
          << duration << " s at " << dt_out << " s";
    }
  }
  EXPECT_GE(accepted, 4);  // 10 s and 100 s at 1e7 − 1 and 1e7 − 2 intervals: not a vacuous loop
  // 10 s at 1 µs is 1e7 intervals, 1e7 + 1 rows with t = 0: the CLI refuses it itself, naming
  // --dt-out (not the simulation's "output rows, more than the limit").
  SimulateArgs over;
  over.duration = 10.0;
  over.dt_out = 1e-6;
  try {
    check_simulate_args(scene, over);
    ADD_FAILURE() << "10 s at 1e-6 s accepted";
  } catch (const ArgumentError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--dt-out", 0), 0u) << e.what();
  }
  // The limit is the same number of rows in every table.
  EXPECT_EQ(static_cast<double>(reduced::kMaxOutputRows), cli_limits::kMaxOutputRows);
  EXPECT_EQ(static_cast<double>(engine::kMaxOutputRows), cli_limits::kMaxOutputRows);
  // --duration at the CLI's bound is a duration the scene may hold.
  EXPECT_LE(cli_limits::kMaxDuration_s, models::limits::kMaxDuration_s);
}

// --grid-deg (simulate, extract, validate): extraction takes the CLI's finest and coarsest grid.
TEST(CliLimits, GridsAtTheCliEdgesAreAcceptedByTheExtraction) {
  EXPECT_EQ(reduced::check_grid_step(cli_limits::kMinGrid_deg * kPi / 180), 36000);
  EXPECT_EQ(reduced::check_grid_step(cli_limits::kMaxGrid_deg * kPi / 180), 4);
  EXPECT_THROW(reduced::check_grid_step(cli_limits::kMinGrid_deg * 0.5 * kPi / 180), reduced::TableError);
}

// drive --motor: a line at the CLI's bounds can be written into a scene (models::limits), and a
// line beyond them cannot.
TEST(CliLimits, MotorLinesAtTheCliBoundsAreValidSceneMotors) {
  auto scene_with_motor = [](double stall, double speed) {
    std::string yaml = R"(
name: motorised
ground_points: {A: [0, 0]}
bodies:
  - {name: crank, mass_kg: 0.5, com_m: [0.05, 0], inertia_kgm2: 4.0e-4}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank}
independent: crank
loads:
  - {type: motor, name: m, joint: crank, stall_torque_Nm: )" + std::to_string(stall) +
                       ", no_load_speed_rad_s: " + std::to_string(speed) + R"(}
gravity: {enabled: false}
initial: {q_deg: 0, qdot: 1.0}
)";
    return models::parse_scene(yaml, "motorised.yaml");
  };
  EXPECT_NO_THROW(scene_with_motor(cli_limits::kMaxMotorStall, cli_limits::kMaxMotorSpeed));
  EXPECT_NO_THROW(scene_with_motor(-cli_limits::kMaxMotorStall, -cli_limits::kMaxMotorSpeed));
  EXPECT_THROW(scene_with_motor(cli_limits::kMaxMotorStall * 1.01, 10.0), models::SceneError);
  EXPECT_THROW(scene_with_motor(10.0, cli_limits::kMaxMotorSpeed * 1.01), models::SceneError);
}

// calibrate's --cadence-hz / --power-w may exceed a scene's (documented in cli_limits.hpp), but
// a scene's whole range is typeable.
TEST(CliLimits, TheScenesCadenceAndPowerRangesAreTypeable) {
  EXPECT_GE(cli_limits::kMaxCadence_Hz, models::limits::kMaxCadence_Hz);
  EXPECT_GE(cli_limits::kMaxPower_W, models::limits::kMaxPower_W);
  EXPECT_LE(cli_limits::kMinGrid_deg, models::limits::kMinGrid_deg);
  EXPECT_GE(cli_limits::kMaxGrid_deg, models::limits::kMaxGrid_deg);
}

}  // namespace
}  // namespace rdyn::validate
