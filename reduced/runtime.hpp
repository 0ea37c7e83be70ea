// The reduced model for embedding in a control loop: load a table checked against its scene,
// make a workspace, then step at a fixed rate with a commanded drive. No Simbody.
//
//   RuntimeModel m = load_runtime_model("bicycle.csv", "bicycle");   // throws, once
//   RuntimeWorkspace ws(m);                                          // allocates, once
//   Status s = step(m, ws, 1e-3, Drive::torque(T_cmd_Nm));           // allocation-free, noexcept
//   ws.get_qdot(), ws.get_forces()[k] ...
//   calc_drive_torque(m, ws, q, qdot, qddot, drive_Nm);                // inverse: feed-forward
//
// step() is the fixed RK4 of reduced_model.hpp (step_fixed_rk4, the same one `rdyn simulate
// --reduced-integrator rk4-fixed` runs) on Eksergian's equation m1 q̈ + m2 q̇² = F*, with the
// scene's joint torques replaced by the drive command. Failures are status codes, never
// exceptions, and a failed step leaves the workspace as it was before the call.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/samples.hpp"
#include "reduced/table.hpp"

namespace rdyn::reduced {

// Outcome of reset() and step(). The numbers are the C API's (rdyn_reduced.h) and stable.
enum class Status : int {
  Ok = 0,
  BadStep = 1,         // dt not finite or outside [kMinFixedStep_s, kMaxFixedStep_s]
  BadDrive = 2,        // drive not finite, a resulting joint torque beyond ±limits::kMaxForce, or a
                       // torque (a scale ≠ 1) commanded to a scene without joint torques
  BadState = 3,        // reset, calc_drive_torque: q, q̇ (q̈) not finite, |q̇| > limits::kMaxRate
                       // (|q̈| > kMaxDriveAcceleration), q outside the table
  WrongWorkspace = 4,  // the workspace was made for a model of another shape
  NonFinite = 5,       // the step produced a non-finite state or output
  LeftTable = 6,       // q left the range of a non-periodic table
  Diverged = 7,        // the energy balance E − E0 = W broke (table or step too coarse)
};
// One sentence for a status (static storage, never null).
const char* status_message(Status s);

// What the controller commands: the scene's joint torques ("drive torques", as `rdyn
// calibrate` scales them) either scaled, or all set to one magnitude T with their scene signs.
struct Drive {
  enum class Mode { Scale, Torque };
  Mode mode = Mode::Scale;
  double value = 1.0;  // Scale: factor [-]; Torque: magnitude T [N·m or N]
  static Drive scaled(double factor) { return {Mode::Scale, factor}; }
  static Drive torque(double magnitude) { return {Mode::Torque, magnitude}; }
};

struct RuntimeOptions {
  // Empty: Fourier for a periodic table (the CLI's default, the more accurate at 10°,
  // docs/theory.md), cubic spline otherwise.
  std::optional<Interpolation> interpolation;
  bool energy_consistent_m2 = false;  // m2 = ½ dm1/dq of the m1 interpolant
};

// The immutable model: the reduced table joined with its scene's loads. A scene that asks for
// joint outputs (outputs.joints, reactions, shaking) is joined as `rdyn extract` and `rdyn
// simulate --model reduced` join it: with the reaction lines its reactions need
// (reduced::with_reaction_requests; `reactions: all`: those the reduced model can give), so the
// table `rdyn extract` wrote for it fits, and the runtime gives the same joint outputs per step.
struct RuntimeModel {
  ReducedModel reduced;                  // its force_names: the scene's, then the reaction lines
  std::vector<std::string> force_names;  // the scene's constraint forces (get_forces' order)
  std::optional<JointOutputModel> joint_outputs;  // none: the scene asks for no joint output
  std::string scene_name;
  bool revolute = true;                  // q in rad (else m)
  double initial_q = 0.0;                // the scene's initial state [rad or m]
  double initial_qdot = 0.0;             // [rad/s or m/s]
  std::vector<std::string> drive_names;  // the scene's joint torques, in Drive order
  std::vector<double> drive_nominal;     // their scene values [N·m or N]
  double potential_min = 0.0;            // min V over the table's grid (divergence guard) [J]
};

// Reads a table written by `rdyn extract` and the scene (a shipped name or a YAML path), and
// joins them. Throws TableError (unreadable or malformed table, a table extracted from
// another scene, missing columns, m1 not positive), models::SceneError (scene).
RuntimeModel load_runtime_model(const std::string& table_path,
                                const std::string& scene_name_or_path,
                                const RuntimeOptions& options = {});
// The same from samples and a scene already in memory.
RuntimeModel make_runtime_model(const Samples& samples, const models::Scene& scene,
                                const RuntimeOptions& options = {});

// Per-run state. Everything is sized in the constructor; reset() and step() allocate nothing.
class RuntimeWorkspace {
 public:
  // At the model's (scene's) initial state with the scene's torques.
  explicit RuntimeWorkspace(const RuntimeModel& model);

  double get_t() const { return state_.t; }        // [s] since the last reset
  double get_q() const { return state_.q; }        // [rad or m]
  double get_qdot() const { return state_.qdot; }  // [rad/s or m/s]
  double get_qddot() const { return qddot_; }      // [rad/s² or m/s²] at (q, q̇), current drive
  double get_work() const { return state_.work; }  // work of the non-conservative loads [J]
  double get_energy() const { return energy_; }    // ½ m1 q̇² + V [J]
  // Constraint forces F_E,k [N] in the order of model.force_names (the scene's).
  const std::vector<double>& get_forces() const { return forces_; }
  // The scene's joint outputs at the current state (q_<j> [rad or m], …, R_<j>_x [N], shaking_x
  // [N], …) in the order of model.joint_outputs->names — what `rdyn simulate --model reduced`
  // writes in its row (reduced::calc_joint_outputs); empty when the scene asks for none.
  const std::vector<double>& get_joint_outputs() const { return joint_out_; }
  // Joint torques applied by the last drive [N·m or N], in the order of model.drive_names.
  const std::vector<double>& get_drive_torques() const { return state_.torque_value; }
  long get_steps() const { return steps_; }        // steps since the last reset
  long get_switches() const { return switches_; }  // steps in which a load gate switched
  const ReducedWorkspace& get_state() const { return state_; }
  // What `s`, just returned by a call on this workspace, means: for BadDrive the one cause of the
  // last refused drive (not finite, no joint torque to command, a torque beyond the limit), for
  // BadState that of the last refused state, else status_message(s). A static string: nothing is
  // allocated.
  const char* describe(Status s) const;

 private:
  friend Status reset(const RuntimeModel&, RuntimeWorkspace&, double, double,
                      const Drive&) noexcept;
  friend Status step(const RuntimeModel&, RuntimeWorkspace&, double, const Drive&) noexcept;
  friend Status calc_drive_torque(const RuntimeModel&, RuntimeWorkspace&, double, double, double,
                                  double&) noexcept;
  bool fits(const RuntimeModel& model) const;
  Status apply_drive(const RuntimeModel& model, const Drive& drive);
  Status calc_outputs(const RuntimeModel& model);

  ReducedWorkspace state_;
  double qddot_ = 0.0, power_nc_ = 0.0, energy_ = 0.0;
  DivergenceGuard guard_;  // divergence guard (reduced_model.hpp)
  std::vector<double> lines_;      // every constraint line of model.reduced (the scene's, then reaction lines)
  std::vector<double> forces_;     // the scene's constraint forces
  std::vector<double> joint_out_;  // the scene's joint outputs
  std::optional<JointOutputWorkspace> joint_ws_;
  long steps_ = 0, switches_ = 0;
  const char* drive_refusal_ = nullptr;  // the last refused drive's cause (apply_drive)
  const char* state_refusal_ = nullptr;  // the last refused state's cause (reset, calc_drive_torque)
  // Scratch for rolling back a failed step.
  ReducedWorkspace saved_;
  std::vector<double> forces_saved_, joint_out_saved_;
  // Scratch for calc_drive_torque, which sets gates of its own and must not touch the state.
  ReducedWorkspace inverse_;
  std::vector<double> forces_inverse_;
};

// Sets t = 0, W = 0, the state (q, q̇) and the drive, and the load gates from that state.
// Returns BadState (q or q̇ not finite or out of range) or BadDrive and leaves the workspace
// unchanged then. Allocation-free.
Status reset(const RuntimeModel& model, RuntimeWorkspace& ws, double q, double qdot,
             const Drive& drive = {}) noexcept;

// Advances by dt [s] with the drive held over the step (one fixed RK4 step; a load switch
// inside it splits the step). Arguments are checked first; on any failure the workspace is
// left as it was. Allocation-free and exception-free.
Status step(const RuntimeModel& model, RuntimeWorkspace& ws, double dt,
            const Drive& drive) noexcept;

// Largest |q̈| calc_drive_torque accepts [rad/s² or m/s²]: limits::kMaxRate reached from rest
// within 1e-4 s.
inline constexpr double kMaxDriveAcceleration = 1e8;

// The inverse of step(): the generalized force the drive must add on q [N·m or N] for the
// reduced model to move with (q, q̇, q̈) — Eksergian's equation solved for it (docs/theory.md
// §11, reduced::calc_drive):
//   drive = m1(q) q̈ + m2(q) q̇² − F*(q, q̇),
// F* holding every load of the scene, with the joint torques as last commanded (the scene's
// values until a reset() or step() commands others) and the load gates set by the sign of q̇
// (of q̈ where q̇ = 0), as `rdyn drive --model reduced` computes each row. A feed-forward
// term for a motor on q. Returns BadState (q, q̇ or q̈ not finite, |q̇| > limits::kMaxRate,
// |q̈| > kMaxDriveAcceleration, q outside the table), WrongWorkspace or NonFinite, and then
// leaves `drive` unchanged. The state (t, q, q̇, gates, outputs) is never changed.
// Allocation-free and exception-free.
Status calc_drive_torque(const RuntimeModel& model, RuntimeWorkspace& ws, double q, double qdot,
                         double qddot, double& drive) noexcept;

}  // namespace rdyn::reduced
