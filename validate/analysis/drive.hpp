// Prescribed motion (`rdyn drive`): the independent coordinate follows a given q(t) — a constant
// rate, or a profile read from a CSV — and each model answers what the drive on q must supply and
// what the constraints carry, with every other load of the scene applied. Full model: inverse
// dynamics, the kinetostatic call with every load on (engine/kinetostatic.hpp). Reduced model: the
// inverse form of Eksergian's equation (reduced::calc_drive). Plain functions returning records;
// the command (validate/cli/drive_command.cpp) writes them.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::validate {

// q(t) and its derivatives on the output grid [s, rad or m].
struct PrescribedMotion {
  std::vector<double> t, q, qdot, qddot;
  std::string how;  // plain words, for run.json
};

// q = q0 + rate·t on [0, duration] every dt (the last row at the duration itself).
PrescribedMotion constant_rate_motion(double q0, double rate, double duration_s, double dt_s);

// One revolution at a constant F rev/s (sign: direction) from q0, rows 1° of q apart (361 rows,
// the last at 1/|F| s): the motion the validate report and `sweep --drive-cadence-hz` drive —
// the rows of `rdyn drive --cadence-hz F --dt-out 1/(360|F|)`.
PrescribedMotion revolution_motion(double q0, double cadence_hz);

// A profile t,q_deg (revolute) or t,q_m (prismatic) from a CSV file, interpolated by a natural
// cubic spline (GSL; q̇ and q̈ its first and second derivatives), sampled every dt from its first
// time over `duration_s` (≤ its span; empty: the span). Throws models::SceneError naming the
// file, the line and the column for an unreadable or malformed profile (fewer than 4 rows, times
// not increasing, a value not finite, the wrong unit for the independent coordinate), or naming
// --duration / --dt-out when the duration exceeds the span or makes more than max_rows rows.
PrescribedMotion profile_motion(const std::string& path, bool revolute, std::optional<double> duration_s, double dt_s,
                                double max_rows = 1e7);

// The full model follows the branch in moves of at most kDriveMove between rows (one
// kinetostatic sample each, ~0.1–0.3 ms); calc_drive_moves counts them for a motion, so the
// command can refuse one that would take hours before any work (kMaxDriveMoves), and a run
// stops after kDriveMaxWall_s all the same.
constexpr double kDriveMove = 5.0 * 3.14159265358979323846 / 180;
// Closest two rows of a profile may be [s]: nearer, the spline's q̇ and q̈ overflow.
constexpr double kMinProfileStep_s = 1e-6;
constexpr double kMaxDriveMoves = 2e5;
constexpr double kDriveMaxWall_s = 600.0;
double calc_drive_moves(const PrescribedMotion& motion);

struct DriveRecord {
  std::vector<double> t, q, qdot, qddot;
  std::vector<double> drive;  // generalized force the drive adds on q [N·m or N]
  std::vector<double> power;  // drive·q̇ [W]
  std::vector<std::string> force_names;
  std::vector<std::vector<double>> forces;  // [force][row] F_E [N]
  // The scene's joint outputs (models::joint_output_names: reactions, shaking, joint motions)
  // along the motion; the reduced model's: those it gives (reduced::split_reduced_reactions).
  std::vector<std::string> column_names;
  std::vector<std::vector<double>> columns;  // [column][row]
  double wall_s = 0.0;
};

// The columns of `rdyn drive`'s CSV in order: t, q, qdot, qddot, drive_Nm (drive_N for a
// prismatic q), drive_W, F_<name> per constraint force, then the joint outputs.
std::vector<std::string> drive_column_names(const std::vector<std::string>& force_names,
                                            const std::vector<std::string>& column_names, bool revolute);
std::vector<std::string> drive_column_names(const DriveRecord& r, bool revolute);
// Column k of that list (k < its size).
const std::vector<double>& drive_column(const DriveRecord& r, size_t k);

// Inverse dynamics of the full model along the motion (continuation from the assembled
// configuration). Throws engine::EngineError where the motion leaves the mechanism's range.
DriveRecord calc_drive_full(const models::Scene& scene, const PrescribedMotion& motion);
// The reduced model's inverse Eksergian equation along the motion. Throws reduced::TableError
// where the motion leaves the table's range.
DriveRecord calc_drive_reduced(const reduced::ReducedModel& model, const PrescribedMotion& motion);
// The same with the joint outputs of `scene` (whose reactions the reduced model gives), the model
// built from reduced::with_reaction_requests(scene): its internal lines become the columns.
DriveRecord calc_drive_reduced(const models::Scene& scene, const reduced::ReducedModel& model,
                               const PrescribedMotion& motion);

struct DriveStats {
  double rms = 0.0, peak = 0.0, mean = 0.0;  // of the drive (peak: largest |drive|)
  // peak_power_W: the largest power the drive delivers (max of drive·q̇, 0 when it only absorbs):
  // what a motor must supply; the braking peak is not in it.
  double mean_power_W = 0.0, peak_power_W = 0.0;
  std::vector<double> force_peaks;  // largest |F_E| per constraint force
};
DriveStats calc_drive_stats(const DriveRecord& r);

// Whether a motor on the independent coordinate, with the torque–speed line
// τ_line(q̇) = stall·(1 − q̇/no_load_speed) (models::motor_torque; stall and no-load speed of one
// sign, as a scene's motor), can give the drive along the motion: at full command it gives the
// line, so it covers a row when the drive lies on the line's side of zero and within it —
// sgn(stall)·(τ_line − drive) ≥ 0 — the catalogue question "is the operating point under the
// torque–speed curve". Margins from the statistics rows (≤ 1° apart), not the output rows.
struct MotorCheck {
  double stall = 0.0, no_load_speed = 0.0;  // [N·m or N], [rad/s or m/s]
  bool covers = false;
  double min_margin = 0.0;                  // smallest sgn(stall)·(τ_line − drive) [N·m or N]
  double at_t = 0.0, at_q = 0.0;            // where it is smallest [s], [rad or m]
  double drive_there = 0.0, line_there = 0.0;  // the drive and the line's torque there
  double min_margin_fraction = 0.0;         // min_margin / |stall|
};
MotorCheck calc_motor_check(const DriveRecord& r, double stall, double no_load_speed);

// The drive over one revolution at a constant rate from both models (the validate report's
// drive figure): the full model's inverse dynamics and the reduced model's inverse Eksergian
// equation on the same rows (revolution_motion), every load of the scene applied.
struct DriveCycleComparison {
  double cadence_hz = 0.0;   // [rev/s]
  double q0 = 0.0;           // [rad]
  DriveRecord full, reduced;  // the same t, q rows
  DriveStats full_stats, reduced_stats;
  double max_difference = 0.0;  // max |drive_reduced − drive_full| over the rows [N·m]
  double rms_difference = 0.0;  // RMS of that difference over the revolution [N·m]
  double grid_deg = 0.0;        // the reduced model's table grid (set by the caller; 0: not said)
};
// `model`: a reduced model built from `scene` (its loads). Throws as calc_drive_full /
// calc_drive_reduced.
DriveCycleComparison calc_drive_cycle_comparison(const models::Scene& scene, const reduced::ReducedModel& model,
                                                 double cadence_hz);

}  // namespace rdyn::validate
