#include "reduced/runtime.hpp"

#include <algorithm>

#include <fmt/format.h>
#include <cmath>

#include "models/scene_yaml.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/simulate_reduced.hpp"

namespace rdyn::reduced {

const char* status_message(Status s) {
  switch (s) {
    case Status::Ok:
      return "ok";
    case Status::BadStep:
      return "step size is not finite or outside [1e-7, 1] s";
    case Status::BadDrive:
      return "drive is not finite, a joint torque it commands exceeds 1e6 N·m (N), or the scene has no joint "
             "torque to command";
    case Status::BadState:
      return "state is not finite, |q̇| exceeds 1e4 rad/s (m/s), or q lies outside the table's "
             "range";
    case Status::WrongWorkspace:
      return "the workspace was made for another model";
    case Status::NonFinite:
      return "the step produced a non-finite state or output; the state was kept";
    case Status::LeftTable:
      return "q left the range of the (non-periodic) table; the state was kept";
    case Status::Diverged:
      return "the reduced model diverges (its energy balance broke): the table or the step is too "
             "coarse; "
             "the state was kept";
  }
  return "unknown status";
}

const char* RuntimeWorkspace::describe(Status s) const {
  if (s == Status::BadDrive && drive_refusal_) return drive_refusal_;
  if (s == Status::BadState && state_refusal_) return state_refusal_;
  return status_message(s);
}

RuntimeModel make_runtime_model(const Samples& samples, const models::Scene& scene,
                                const RuntimeOptions& options) {
  const Interpolation interp = options.interpolation.value_or(
      samples.periodic ? Interpolation::Fourier : Interpolation::CubicSpline);
  RuntimeModel m;
  // Joint outputs as `rdyn extract` and `rdyn simulate --model reduced` give them: the scene with
  // the reaction lines they need (its hash is the table's), `reactions: all` those it can give.
  const models::Scene oscene = scene.outputs.reactions_all ? split_reduced_reactions(scene).scene : scene;
  const bool joints = wants_joint_outputs(oscene);
  m.reduced = make_reduced_model(samples, joints ? with_reaction_requests(oscene) : scene, interp,
                                 options.energy_consistent_m2);  // checks the scene hash
  for (const auto& f : scene.outputs.constraint_forces) m.force_names.push_back(f.name);  // first in reduced's
  if (joints) m.joint_outputs = make_joint_output_model(oscene, m.reduced.table, m.reduced.force_names);
  // The runtime gives every constraint force at every step, with no way to leave one out near
  // a pole (check_force_poles): a table with one is refused here rather than answered wrongly.
  for (size_t k = 0; k < m.reduced.force_poles.size(); ++k)
    if (!m.reduced.force_poles[k].empty())
      throw TableError(fmt::format("the runtime cannot give constraint force '{}': its table parameters have a "
                                   "pole at a singular configuration ({}); leave it out of the scene's outputs",
                                   m.reduced.force_names[k], describe_q(m.reduced.revolute, m.reduced.force_poles[k][0])));
  m.potential_min = calc_potential_min(m.reduced);
  m.scene_name = scene.name;
  m.revolute = samples.revolute;
  m.initial_q = scene.initial.q;
  m.initial_qdot = scene.initial.qdot;
  for (const auto& t : scene.joint_torques) {
    m.drive_names.push_back(t.name);
    m.drive_nominal.push_back(t.value);
  }
  return m;
}

RuntimeModel load_runtime_model(const std::string& table_path,
                                const std::string& scene_name_or_path,
                                const RuntimeOptions& options) {
  const models::Scene scene = models::load_scene(scene_name_or_path);
  return make_runtime_model(read_samples_csv(table_path), scene, options);
}

RuntimeWorkspace::RuntimeWorkspace(const RuntimeModel& model)
    : state_(model.reduced),
      lines_(model.reduced.force_names.size()),
      forces_(model.force_names.size()),
      joint_out_(model.joint_outputs ? model.joint_outputs->names.size() : 0),
      saved_(model.reduced),
      forces_saved_(forces_.size()),
      joint_out_saved_(joint_out_.size()),
      inverse_(model.reduced),
      forces_inverse_(model.reduced.force_names.size()) {
  if (model.joint_outputs) joint_ws_.emplace(*model.joint_outputs);
  // The scene's initial state was checked with the scene (limits::kMaxRate, kMaxAngle_rad);
  // a non-periodic table may still not cover it, which the first reset() would report.
  if (reset(model, *this, model.initial_q, model.initial_qdot) != Status::Ok) {
    state_.q = model.initial_q, state_.qdot = model.initial_qdot;
  }
}

bool RuntimeWorkspace::fits(const RuntimeModel& model) const {
  const auto& m = model.reduced;
  return state_.gate_on.size() == m.gates.size() &&
         state_.torque_value.size() == m.torques.size() &&
         state_.scratch.size() == m.rhs_cols.size() &&
         state_.scratch_out.size() == m.out_cols.size() &&
         state_.scratch_rec.size() == m.record_cols.size() &&
         lines_.size() == m.force_names.size() && forces_.size() == model.force_names.size() &&
         joint_out_.size() == (model.joint_outputs ? model.joint_outputs->names.size() : 0) &&
         joint_ws_.has_value() == model.joint_outputs.has_value() &&
         inverse_.scratch_rec.size() == m.record_cols.size() &&
         inverse_.gate_on.size() == m.gates.size() &&
         inverse_.torque_value.size() == m.torques.size() &&
         forces_inverse_.size() == m.force_names.size();
}

// Checks the whole command before writing any torque, so a refused drive changes nothing.
Status RuntimeWorkspace::apply_drive(const RuntimeModel& model, const Drive& drive) {
  const auto& torques = model.reduced.torques;
  auto commanded = [&](size_t i) {
    const double nominal = torques[i].value;
    return drive.mode == Drive::Mode::Scale ? drive.value * nominal
                                            : (nominal < 0 ? -1.0 : 1.0) * drive.value;
  };
  auto refuse = [&](const char* why) {
    drive_refusal_ = why;
    return Status::BadDrive;
  };
  if (!std::isfinite(drive.value)) return refuse("the drive's value is not finite (or its mode is unknown)");
  // A scene without joint torques has nothing to command: a torque (or a scale other than the
  // scene's own) would be ignored in silence, and the caller's controller would run open loop.
  if (torques.empty() && !(drive.mode == Drive::Mode::Scale && drive.value == 1.0))
    return refuse("the scene has no joint torque for the drive to command (only a scale of 1 is accepted)");
  for (size_t i = 0; i < torques.size(); ++i)
    if (!(std::abs(commanded(i)) <= models::limits::kMaxForce))
      return refuse("a joint torque the drive commands exceeds 1e6 N·m (N)");
  for (size_t i = 0; i < torques.size(); ++i) state_.torque_value[i] = commanded(i);
  return Status::Ok;
}

// q̈, energy and constraint forces at the current state from one fused table lookup, then the
// joint outputs from them (the rows' route, reduced::calc_joint_outputs).
Status RuntimeWorkspace::calc_outputs(const RuntimeModel& model) {
  double qddot, power;
  const double energy =
      calc_sample(model.reduced, state_, state_.q, state_.qdot, qddot, power, lines_.data());
  std::copy(lines_.begin(), lines_.begin() + static_cast<std::ptrdiff_t>(forces_.size()), forces_.begin());
  if (model.joint_outputs)
    calc_joint_outputs(*model.joint_outputs, model.reduced.table, *joint_ws_, state_.q, state_.qdot, qddot,
                       lines_.data(), joint_out_.data());
  bool finite = std::isfinite(qddot) && std::isfinite(power) && std::isfinite(energy);
  for (double f : forces_) finite = finite && std::isfinite(f);
  for (double f : joint_out_) finite = finite && std::isfinite(f);
  if (!finite) return Status::NonFinite;
  qddot_ = qddot, power_nc_ = power, energy_ = energy;
  return Status::Ok;
}

namespace {

// Copies the stepping state (not the scratch space) from one workspace into another of the
// same model; no allocation, as both vectors already have their sizes.
void copy_state(const ReducedWorkspace& from, ReducedWorkspace& to) {
  to.t = from.t, to.q = from.q, to.qdot = from.qdot, to.work = from.work;
  std::copy(from.gate_on.begin(), from.gate_on.end(), to.gate_on.begin());
  std::copy(from.torque_value.begin(), from.torque_value.end(), to.torque_value.begin());
}

// The one cause of a refused state (q, q̇, q̈; q̈ = 0 where there is none), nullptr when it is
// accepted: a static text for RuntimeWorkspace::describe.
const char* state_refusal(const RuntimeModel& model, double q, double qdot, double qddot) {
  const double q_max = model.revolute ? models::limits::kMaxAngle_rad : models::limits::kMaxCoordinate_m;
  if (!std::isfinite(q) || !std::isfinite(qdot) || !std::isfinite(qddot)) return "the state is not finite";
  if (!(std::abs(q) <= q_max)) return "q is beyond the coordinate's limit (1e6 rad or m)";
  if (!(std::abs(qdot) <= models::limits::kMaxRate)) return "|q̇| exceeds 1e4 rad/s (m/s)";
  if (!(std::abs(qddot) <= kMaxDriveAcceleration)) return "|q̈| exceeds 1e8 rad/s² (m/s²)";
  if (!model.reduced.table.in_range(q)) return "q lies outside the table's range";
  return nullptr;
}

}  // namespace

Status reset(const RuntimeModel& model, RuntimeWorkspace& ws, double q, double qdot,
             const Drive& drive) noexcept {
  if (!ws.fits(model)) return Status::WrongWorkspace;
  if (const char* why = state_refusal(model, q, qdot, 0.0)) {
    ws.state_refusal_ = why;
    return Status::BadState;
  }
  copy_state(ws.state_, ws.saved_);
  std::copy(ws.forces_.begin(), ws.forces_.end(), ws.forces_saved_.begin());
  std::copy(ws.joint_out_.begin(), ws.joint_out_.end(), ws.joint_out_saved_.begin());
  if (const Status s = ws.apply_drive(model, drive); s != Status::Ok) return s;
  auto& st = ws.state_;
  st.t = 0.0, st.q = q, st.qdot = qdot, st.work = 0.0;
  init_gates(model.reduced, st);
  if (const Status s = ws.calc_outputs(model); s != Status::Ok) {
    copy_state(ws.saved_, ws.state_);
    std::copy(ws.forces_saved_.begin(), ws.forces_saved_.end(), ws.forces_.begin());
    std::copy(ws.joint_out_saved_.begin(), ws.joint_out_saved_.end(), ws.joint_out_.begin());
    return s;
  }
  ws.guard_ = start_divergence_guard(ws.energy_, model.potential_min, 0.0);
  ws.steps_ = ws.switches_ = 0;
  return Status::Ok;
}

Status step(const RuntimeModel& model, RuntimeWorkspace& ws, double dt,
            const Drive& drive) noexcept {
  if (!ws.fits(model)) return Status::WrongWorkspace;
  if (!(dt >= kMinFixedStep_s && dt <= kMaxFixedStep_s)) return Status::BadStep;
  const auto& m = model.reduced;
  auto& st = ws.state_;
  copy_state(st, ws.saved_);
  std::copy(ws.forces_.begin(), ws.forces_.end(), ws.forces_saved_.begin());
  std::copy(ws.joint_out_.begin(), ws.joint_out_.end(), ws.joint_out_saved_.begin());
  const double qddot0 = ws.qddot_, power0 = ws.power_nc_, energy0 = ws.energy_;
  if (const Status s = ws.apply_drive(model, drive); s != Status::Ok) return s;

  const double t_switch = step_fixed_rk4(m, st, dt);
  Status s = Status::Ok;
  if (!std::isfinite(st.q) || !std::isfinite(st.qdot) || !std::isfinite(st.work))
    s = Status::NonFinite;
  else if (!m.table.in_range(st.q))
    s = Status::LeftTable;
  else
    s = ws.calc_outputs(model);
  const DivergenceGuard guard0 = ws.guard_;
  if (s == Status::Ok && divergence_guard_fires(ws.guard_, ws.energy_, st.work)) s = Status::Diverged;
  if (s != Status::Ok) {  // roll back: the caller sees the state before the call
    copy_state(ws.saved_, st);
    std::copy(ws.forces_saved_.begin(), ws.forces_saved_.end(), ws.forces_.begin());
    std::copy(ws.joint_out_saved_.begin(), ws.joint_out_saved_.end(), ws.joint_out_.begin());
    ws.qddot_ = qddot0, ws.power_nc_ = power0, ws.energy_ = energy0;
    ws.guard_ = guard0;
    return s;
  }
  ++ws.steps_;
  if (!std::isnan(t_switch)) ++ws.switches_;
  return Status::Ok;
}

Status calc_drive_torque(const RuntimeModel& model, RuntimeWorkspace& ws, double q, double qdot,
                         double qddot, double& drive) noexcept {
  if (!ws.fits(model)) return Status::WrongWorkspace;
  if (const char* why = state_refusal(model, q, qdot, qddot)) {
    ws.state_refusal_ = why;
    return Status::BadState;
  }
  // The joint torques as commanded now; gates of its own (calc_drive sets them from q̇, q̈).
  std::copy(ws.state_.torque_value.begin(), ws.state_.torque_value.end(),
            ws.inverse_.torque_value.begin());
  double power_nc = 0.0;
  const double d =
      calc_drive(model.reduced, ws.inverse_, q, qdot, qddot, power_nc, ws.forces_inverse_.data());
  if (!std::isfinite(d)) return Status::NonFinite;
  drive = d;
  return Status::Ok;
}

}  // namespace rdyn::reduced
