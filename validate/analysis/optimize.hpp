// The drive-load shape that minimises a constraint force (issue #13, `rdyn optimize`): the
// shape of one or more drive loads as truncated Fourier series of a revolute joint's angle,
//   τ(θ) = a0 + Σ_{k=1..H} a_k cos kθ + b_k sin kθ,
// each load keeping its rate gate, searched by NLopt's COBYLA on the reduced model's steady
// cycle. Per candidate shape the loads' common amplitude is calibrated (calibrate_reduced: the
// mean cadence F, with the resistance dissipating P at F), so the objective — the peak |F_E| of
// the chosen constraint force over the steady cycle, or its p-norm (mean |F_E|^p)^(1/p) — is
// compared at the same operating point. The table is extracted once; a shape changes only the
// tau_<load> columns (reduced/profile_columns.hpp). The constant strategy and the optimum are
// then each simulated with the full model (docs/theory.md, "Pedalling optimisation").
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/analysis/fourier_minimum.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {

// Ranges of the options (SceneError naming the option, before any work).
inline constexpr int kMaxOptimizeEvaluations = 100000;
inline constexpr double kMinOptimizeFullDuration_s = 4.0, kMaxOptimizeFullDuration_s = 600.0;

struct OptimizeOptions {
  double cadence_hz = 1.0;  // mean cadence the amplitude holds [rev/s]
  double power_w = 0.0;     // > 0: the one resistance dissipates it at F (calibrate's power mode)
  // Overrides of the scene's optimize block (unset: the block's, else its defaults).
  int harmonics = 0;         // 0: the block's
  std::string objective;     // "": the block's; peak | pnorm
  double p = 0.0;            // 0: the block's
  double max_load = 0.0;     // 0: the block's
  std::string force_name;    // "": the block's
  // Extra design loads: a profiled joint torque on each named revolute joint (name
  // torque_<joint>), a signed shape of its own, bounded by add_torque_max [N·m].
  std::vector<std::string> add_torques;
  double add_torque_max = 50.0;
  int max_evaluations = 400;   // objective evaluations by the optimiser, [1, kMaxOptimizeEvaluations]
  double rel_tolerance = 1e-4; // NLopt's relative tolerance on the parameters and the objective
  double grid_deg = 10.0;
  bool grid_given = true;  // false: a default, halved while it does not resolve m1 (extract_resolving)
  std::string interpolation = "fourier";
  double full_duration_s = 20.0;  // each full-model confirmation run [s]
  double full_skip_s = 2.0;       // the window starts after this [s] (whole revolutions from there)
};

// One strategy over the crank (independent coordinate) angle, for the profile CSV and report:
// computed from the same calibrated scene (load values, resistance coefficient, table) as the
// strategy's numbers.
struct StrategyCurves {
  std::vector<double> angle_deg;               // q mod 360° of the samples [deg]
  std::vector<std::vector<double>> torque_Nm;  // per design load: applied value·τ(θ)·gate [N·m or N]
  std::vector<double> force_reduced_N;         // the optimised force over one steady cycle (reduced)
  std::vector<double> force_full_N;            // the same from the full model's last revolution
};

struct StrategyResult {
  double amplitude = 0.0;          // calibrated common value of the design loads [N·m or N]
  // The resistance's coefficient this strategy's steady cycle dissipates P with (calibrated with
  // its amplitude; NaN in mean-speed mode): its curves and full run use this one.
  double resistance_coefficient = NAN;
  double peak_reduced_N = 0.0;     // max |F| over the reduced steady cycle
  double objective_reduced = 0.0;  // peak or p-norm over the reduced cycle [N]
  double cadence_reduced_hz = 0.0;
  double cadence_full_hz = 0.0;    // mean over whole revolutions of the full run after full_skip_s
  double peak_full_N = 0.0;        // max |F| over that window (full model)
  double max_torque_Nm = 0.0;      // max over design loads and angles of |value·τ(θ)|
  double mean_power_w = 0.0;       // drive power over the reduced steady cycle
  double steady_q = 0.0, steady_qdot = 0.0;
  // Shape coefficients per design load (tied loads: the shifted series written out).
  std::vector<double> a0;
  std::vector<std::vector<double>> a, b;
  StrategyCurves curves;
};

struct OptimizeResult {
  std::string scene, force_name, objective, optimiser = "NLopt COBYLA", profile_of;
  std::string independent;     // the angle the curves run over
  double full_duration_s = 0;  // each full-model run [s]
  double p = 0.0;
  int harmonics = 0;
  double max_load = 0.0, resistance_coefficient = 0.0, cadence_hz = 0.0, power_w = 0.0;
  double grid_deg = 0.0;                  // the table's grid (OptimizeOptions::grid_deg, or finer when refined)
  std::vector<std::string> design_loads;  // names, in scene order of the optimised scene
  std::vector<std::string> same_as;       // per design load: the load it is tied to ("" none)
  std::vector<double> shift_deg;
  std::vector<std::string> added_loads;   // added by --add-torque
  // The largest lift δ of a nonnegative shape after the search (COBYLA meets constraints to its
  // tolerance): τ → τ + δ, or (τ + δ)/(1 + δ) for the first shape (a0 ≡ 1); 0 when none was needed.
  double nonnegative_repair = 0.0;
  StrategyResult constant, optimised;
  double reduction_reduced = 0.0, reduction_full = 0.0;  // 1 − after/before of the peak
  double agreement = 0.0;  // |peak_full − peak_reduced| / peak_full at the optimum
  int evaluations = 0, failed_evaluations = 0;
  std::string stop_reason;
  double optimise_wall_s = 0.0, wall_time_s = 0.0;
  bool full_cadence_ok = false, full_better = false;
  models::Scene optimised_scene;  // design loads profiled at the optimum, amplitude, resistance, steady start
  models::Scene constant_scene;   // the same for the constant strategy (its full run's scene)
};

// The design resolved from the scene's optimize block and the options (every name checked,
// SceneError naming the field or option): the scene with the added torques.
models::Scene scene_with_added_torques(const models::Scene& scene, const OptimizeOptions& opt);
void check_optimize_options(const models::Scene& scene, const OptimizeOptions& opt);

// Runs the search and both full-model confirmations. Throws SceneError/EngineError/TableError on
// bad input (exit 2) and NumericalError when the constant strategy cannot be calibrated or a
// full run fails. A result that misses its target (full cadence off by > 1 %, or the optimum not
// better on the full model) is returned with full_cadence_ok / full_better false: the caller
// writes nothing and exits 1 (optimize_failure_message).
OptimizeResult optimize(const models::Scene& scene, const OptimizeOptions& opt, Progress& progress);

// Empty when the result met its targets; else what was missed, with the values reached.
std::string optimize_failure_message(const OptimizeResult& r);

}  // namespace rdyn::validate
