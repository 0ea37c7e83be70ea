// Calibration of one drive load to an operating point: find the value of a named load (a joint
// torque, a prismatic joint's force, or a motor's stall torque with its no-load speed kept) —
// or of every joint torque together, signs kept — that holds the mean steady rate of the
// independent coordinate at F revolutions per second. Two operating points: with a power P the
// scene's one resistance's coefficient is set too, so that it dissipates P on average over the
// steady cycle at F (c = P/ω_Fⁿ is exact only at constant speed); without, the resistances stay
// as given. Solved on the reduced model, confirmed with the full model. The reduced part is one
// Newton iteration on the first integral for the steady cycle, the load and the coefficient
// together (validate/analysis/operating_point.hpp); where it does not converge, the nested searches:
// GSL Brent on the load value (each value a steady-cycle search) inside a secant on ln c.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/extract.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/samples.hpp"
#include "reduced/table.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {

struct CalibrationOptions {
  double cadence_hz = 1.0;  // target mean rate of q [rev/s]
  double power_w = 0.0;     // 0: mean speed only (resistances as given); > 0: the resistance dissipates it at F
  std::string load;         // a joint_torque, point_force or motor name, or names joined by '+'; empty: every joint torque together
  std::string load_field = "--load";  // where `load` came from (named in refusals)
  double grid_deg = 10.0;
  // false: grid_deg is a default, halved while the table does not resolve m1 (extract_resolving,
  // validate/analysis/build_reduced.hpp); true: the user's (--grid-deg, the scene's grid_deg).
  bool grid_given = true;
  std::string interpolation = "fourier";
  double tolerance = 1e-10;    // reduced integrator
  // Full-model confirmation from the reduced steady cycle's point: run until the mean cadence
  // over whole revolutions is steady, at most this simulated time [s] (0: no confirmation).
  double full_max_s = 120.0;
  // A full-model miss (not steady by the cap, or steady off F by more than 1 %) is a
  // NumericalError; with this set it is returned instead, in CalibrationResult::unconfirmed
  // (`calibrate --write-scene FILE --force` writes the scene, then exits 1 with the message).
  bool keep_unconfirmed = false;
  // The operating point by one Newton iteration on the first integral (validate/analysis/operating_point.hpp);
  // false, or where it does not converge: the nested searches (Brent on the load, each value a
  // fixed-point search, a secant on the coefficient around them), the cross-check.
  bool direct = true;
};

struct CalibrationResult {
  std::string load;       // the load's name; every joint torque: their names joined by '+'
  std::string load_kind;  // joint_torque | joint_force | point_force | motor_stall_torque | motor_stall_force |
                          // joint_torques; '+' lists: point_forces | joint_torques | loads
  std::string load_unit;  // N·m or N
  double load_value = 0.0;  // calibrated value, signed (joint_torques: the magnitude each gets, signs kept)
  double torque_Nm = 0.0;   // = |load_value| for joint torques on revolute joints, NaN for other kinds
  double initial_guess = 0.0;           // from the energy balance per revolution [load unit] (power mode: at the
                                        // starting coefficient P/ω_Fⁿ)
  // c0, c1 or c2 of the scene's resistance (NaN: mean-speed mode, unchanged): the one whose
  // steady cycle at F dissipates P on average (not P/ω_Fⁿ, which holds only at constant speed).
  double resistance_coefficient = 0.0;
  double mean_cadence_hz_reduced = 0.0;
  // Mean over the full model's last 3 whole revolutions once steady [rev/s] (NaN when the check
  // was skipped).
  double mean_cadence_hz_full = 0.0;
  // The full-model miss's message when opt.keep_unconfirmed kept it (empty: confirmed or skipped).
  std::string unconfirmed;
  int full_revolutions = 0;              // whole revolutions the full model's confirming run made
  double full_duration_s = 0.0;          // simulated time of that run [s] (0: skipped)
  double mean_power_w = 0.0;            // mean power of the calibrated load over the steady cycle (reduced)
  // Mean power the resistances dissipate over the steady cycle (reduced) [W]: = P in power mode
  // (to 1e-8; the coefficient is adjusted until it is), whatever the speed fluctuation.
  double mean_dissipated_power_w = 0.0;
  std::string force_name;               // first requested constraint force (empty if none)
  double peak_force_N = 0.0;            // max |F| over the steady cycle (reduced)
  double peak_force_full_N = 0.0;
  std::vector<double> peak_forces_N;   // max |F| of every requested constraint force, in order (reduced)
  double speed_fluctuation = 0.0;       // (max − min)/mean of q̇ over the steady cycle (reduced)
  double speed_fluctuation_full = 0.0;
  // Work of the load per revolution per unit of its value at the constant target rate [J per
  // N·m or N]: Σ ∫ r_j·gate dq (joint torques: exact, the gated joints' swing in rad or stroke
  // in m), ∫ (1 − r q̇/ω0) r dq (motors).
  double work_per_rev_per_unit = 0.0;
  double steady_q = 0.0, steady_qdot = 0.0;  // a point of the steady cycle (initial conditions)
  double grid_deg = NAN;                // the table's grid [deg] (opt.grid_deg, or finer when refined)
  int evaluations = 0;                  // steady cycles computed
  int load_searches = 0;                // Brent searches of the load value (power mode: one per coefficient tried)
  double wall_time_s = 0.0;
};

// The options for `scene`: each of cadence_hz, power_w (0: not given) and load (empty: not
// given) from the command line, else from the scene's validation.calibrate block (cadence_Hz,
// power_W, load; a missing power means mean-speed mode). cadence_hz stays 0 when neither
// gives it. load_field names where the load came from.
CalibrationOptions calibration_options_of(const models::Scene& scene, double cadence_hz, double power_w,
                                          const std::string& load);

// The CSV column of the calibrated value in a sweep: drive_torque_Nm for joint torques on
// revolute joints (the column's name before loads were named), else <kind>_<unit>
// (joint_force_N, motor_stall_torque_Nm, motor_stall_force_N, drive_force_N, drive_load).
std::string load_value_column(const models::Scene& scene, const CalibrationOptions& opt);

// Checks that `scene` can be calibrated at all and that it assembles; throws models::SceneError
// (naming opt.load_field, "loads" or the option) / engine::EngineError (bad input) otherwise:
// an unknown load or one that is not a joint torque or motor; no joint torque when no load is
// named; with a power, not exactly one resistance turning at a fixed ratio to q. Cheap: sweeps
// call it on the base scene before any case runs. Refusals that need the table (a load doing
// no net work per revolution, a motor whose joint would turn beyond its no-load speed) come
// from calibrate().
void check_calibratable(const models::Scene& scene, const CalibrationOptions& opt);

// The coefficient of the scene's one resistance that dissipates opt.power_w at opt.cadence_hz
// (P = c·ωⁿ, ω the resistance body's rate); NaN in mean-speed mode (no power).
double calc_resistance_coefficient(const models::Scene& scene, const CalibrationOptions& opt);

// `scene` with the load(s) opt.load selects at unit value (signs kept) and, with a power, the
// resistance coefficient set: the scene whose reduced model calibrate_reduced takes.
models::Scene with_unit_load(const models::Scene& scene, const CalibrationOptions& opt);

// calibrate()'s reduced part on a model already built from the scene's table and
// with_unit_load(scene, opt): the first guess from the energy balance per revolution, the
// refusals that need the table (SceneError), the operating point (Newton on the first integral,
// or the nested searches), the steady cycle there (extremes and peak forces). `m` is not
// changed: the searches run on a copy, and the values found (load_value, resistance_coefficient)
// are the result's, to be passed on; the full-model fields are NaN.
// Does not call check_calibratable (the caller has). Throws NumericalError when no value
// reaches F to 1e-6. A search over load shapes calls it once per shape on the same table.
CalibrationResult calibrate_reduced(const reduced::ReducedModel& m, const models::Scene& scene,
                                    const CalibrationOptions& opt, Progress& progress);
// The same on a model the calibration owns and changes (calibrate() passes the one it builds;
// the const& overload a copy, so a caller's model is never left at some shape's values — issue
// #23: a model shared by two strategies kept the last one's coefficient): no copy of its table and column blocks (~2 MB at 10° fourier, resampled at 0.25°;
// the copy, with its page faults, was ~10 % of a sweep case over the rider's height).
CalibrationResult calibrate_reduced(reduced::ReducedModel&& m, const models::Scene& scene,
                                    const CalibrationOptions& opt, Progress& progress);

// The calibration's table: the kinetostatic extraction at opt.grid_deg and its interpolant
// (opt.interpolation). It depends on the mechanism and where loads act, not on load values,
// resistance coefficients, cadence or power (the scene hash, models/scene_hash.hpp): scenes
// that differ only there share it. Throws as calibrate() for a scene that cannot be calibrated.
struct CalibrationTable {
  reduced::Samples samples;
  reduced::Table table;
  bool walked = true;  // the dead-point walk ran (false: its neighbour's continuation stood in for it)
  double grid_deg = 0.0;  // its grid [deg]: opt.grid_deg, or finer when a default grid was refined
};
CalibrationTable extract_calibration_table(const models::Scene& scene, const CalibrationOptions& opt);

// A sweep's previous table on its thread (issue #28 item 3, continuation in the parameters):
// what the next case needs to know to skip the dead-point walk.
struct TableNeighbour {
  std::string topology;           // topology_key of its scene
  double min_conditioning = 0.0;  // the smallest loop conditioning over its grid samples
};

// The joints, loops, gears and independent joint by name and kind, without any number: two
// scenes of a sweep over sizes, masses or positions share it; one whose axis adds a leg does not.
std::string topology_key(const models::Scene& scene);

// The neighbour a table leaves for the next case of a sweep (a periodic table only; none
// otherwise, so the next case walks).
std::optional<TableNeighbour> neighbour_of(const models::Scene& scene, const CalibrationTable& table);

// When a case may skip the dead-point walk: its neighbour's and its own smallest grid
// conditioning at least kWalkSkipConditioning, and its own at least kWalkSkipDrop of the
// neighbour's. A dead point is rank loss of the loop Jacobian (conditioning 0), and the
// conditioning rises like the square root of the distance from it, so a blocked range hiding
// between two grid points pulls the grid samples beside it down. The floor is the extraction's
// own (reduced::kScanBelowConditioning: below it rank loss may lie between grid points, and it
// scans); the drop catches a dead point approaching as the parameter changes. A heuristic, not a
// proof: measured, the narrow blocked four-bar whose 20° sweep closes over its blocked range
// shows 0.016–0.020 after free-turning neighbours at 0.065–0.26; the bicycle 0.060 at every
// rider height of 1.5–2.0 m (tests/validate/analysis/calibrate_test.cpp).
inline constexpr double kWalkSkipConditioning = reduced::kScanBelowConditioning;
inline constexpr double kWalkSkipDrop = 0.5;

// extract_calibration_table for a sweep's next case. With a neighbour of the same topology whose
// grid stayed at or above kWalkSkipConditioning, the extraction runs first and the walk only
// when it fails, meets a dead point, or its own grid comes below kWalkSkipConditioning or below
// kWalkSkipDrop of the neighbour's: the
// extraction's sweep traverses the same turn in the same 10° moves. A case that skips the walk
// gets the same table (the walk changes nothing in it); one that fails gets the same error as
// the cold route (the walk, run before the error is passed on, refuses dead points first).
// `columns` set: the table's samples keep only those columns (reduced::select_columns) and only
// they are fitted — a sweep fits what its cases read (validate/analysis/sweep_peaks.hpp,
// sweep_table_columns), with the same values in them as the whole table (issue #28 item 3).
CalibrationTable extract_calibration_table(const models::Scene& scene, const CalibrationOptions& opt,
                                           const std::optional<TableNeighbour>& neighbour,
                                           const std::optional<std::vector<std::string>>& columns = std::nullopt);

// calibrate() on a table already extracted for a scene of the same hash (sweeps whose axes vary
// only load values reuse one; reduced::TableError when the hashes differ).
CalibrationResult calibrate(const models::Scene& scene, const CalibrationTable& table, const CalibrationOptions& opt,
                            Progress& progress);

// Throws as check_calibratable (its full-model part from the extraction itself: the assembly
// names a loop that cannot close, the sweep of the full turn meets dead points), and
// models::NumericalError when no value reaches F or the result misses its target (reduced
// 1e-6, full 1 % of F).
CalibrationResult calibrate(const models::Scene& scene, const CalibrationOptions& opt, Progress& progress);

}  // namespace rdyn::validate
