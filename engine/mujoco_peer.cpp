#include "engine/mujoco_peer.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <optional>

#include "models/gear_fold.hpp"
#include "models/mjcf_export.hpp"

#ifdef RDYN_HAVE_MUJOCO
#include <mujoco/mujoco.h>
#endif

namespace rdyn::engine {

namespace {

void check_settings(const MujocoSettings& s) {
  if (!(std::isfinite(s.timestep_s) && s.timestep_s > 0))
    throw EngineError(fmt::format("MuJoCo peer: time step {} s must be positive and finite", s.timestep_s));
  if (s.integrator != "euler" && s.integrator != "rk4")
    throw EngineError("MuJoCo peer: unknown integrator '" + s.integrator + "' (euler, rk4)");
  if (!(std::isfinite(s.timeconst_s) && s.timeconst_s >= 0))
    throw EngineError(fmt::format("MuJoCo peer: constraint time constant {} s must be ≥ 0", s.timeconst_s));
  if (!(s.impedance > 0 && s.impedance < 1))
    throw EngineError(fmt::format("MuJoCo peer: constraint impedance {} must be in (0, 1)", s.impedance));
}

}  // namespace

double calc_peer_step(double step_s, double output_interval_s) {
  const double n = std::ceil(output_interval_s / step_s - 1e-9);
  return output_interval_s / std::max(1.0, n);
}

#ifndef RDYN_HAVE_MUJOCO

bool mujoco_available() { return false; }
std::string mujoco_version() { return ""; }

struct MujocoModel::Impl {
  MujocoSettings settings;
  std::string mjcf;
};

MujocoModel::MujocoModel(const models::Scene&, const std::vector<double>&, const MujocoSettings&) {
  throw EngineError("MuJoCo was not found when rdyn was built (CMake looked for libmujoco and mujoco/mujoco.h)");
}
MujocoModel::~MujocoModel() = default;
const MujocoSettings& MujocoModel::settings() const { return impl_->settings; }
const std::string& MujocoModel::mjcf() const { return impl_->mjcf; }

models::TimeSeries simulate_mujoco(const MujocoModel&, const MujocoRunOptions&) {
  throw EngineError("MuJoCo was not found when rdyn was built");
}

#else

bool mujoco_available() { return true; }
std::string mujoco_version() { return mj_versionString(); }

namespace {

// A fold: joint driven_joint turns at `ratio` times joint driver_joint (+ q_offset), its body
// built into the driver's (models/gear_fold.hpp).
using Fold = models::GearFold;

// MuJoCo reports fatal errors through mju_error, which by default prints and exits the process:
// rdyn turns them into exceptions (MuJoCo is built with unwind tables on Debian's x86-64 and
// arm64 defaults) so that a failed run is an exit status 1, never a silent exit.
[[noreturn]] void throw_mujoco_error(const char* msg) {
  throw models::NumericalError(std::string("MuJoCo: ") + msg);
}
void ignore_mujoco_warning(const char*) {}  // counted in mjData::warning, checked after each step

struct Run;
thread_local Run* current_run = nullptr;  // the run whose loads the control callback applies
void apply_loads_callback(const mjModel*, mjData*);

void install_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = throw_mujoco_error;
    mju_user_warning = ignore_mujoco_warning;
    // Called at every evaluation of the dynamics, including each stage of RK4, after positions
    // and velocities and before the accelerations: the loads see the stage's own state.
    mjcb_control = apply_loads_callback;
  });
}

}  // namespace

struct MujocoModel::Impl {
  models::Scene scene;
  MujocoSettings settings;
  std::string mjcf;
  mjModel* m = nullptr;
  std::vector<int> joint_qadr, joint_dof;  // per scene joint; −1 when folded
  std::vector<std::optional<Fold>> joint_fold;
  std::vector<int> body_id;                     // per scene body; −1 when folded
  std::vector<std::optional<Fold>> body_fold;   // folded body: its rate = ratio · rate(driver)
  std::vector<int> request_body;                // per constraint force: the joint's child
  std::vector<models::Vec2> request_dir;        // unit, child frame
  int independent = -1;

  ~Impl() {
    if (m) mj_deleteModel(m);
  }
  int body_of(const std::string& name) const {
    return name == models::kGround ? 0 : body_id[scene.body_index(name)];
  }
};

namespace {

// Compiles the MJCF text from memory (MuJoCo's virtual file system: no temporary file).
mjModel* load_from_memory(const std::string& xml) {
  auto vfs = std::make_unique<mjVFS>();  // ~2 MB of file-name slots: on the heap
  mj_defaultVFS(vfs.get());
  const char* name = "rdyn_scene.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), name, static_cast<int>(xml.size())) != 0)
    throw EngineError("MuJoCo peer: cannot create the model in MuJoCo's virtual file system");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name)], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* m = mj_loadXML(name, vfs.get(), error, sizeof error);
  mj_deleteVFS(vfs.get());
  if (!m) throw EngineError(std::string("MuJoCo refused the exported model: ") + error);
  return m;
}

// One simulation's workspace: MuJoCo's data, and the loads' bookkeeping.
struct Run {
  const MujocoModel::Impl& model;
  mjData* d = nullptr;
  // Work integral of the non-conservative loads with the integrator's stage weights.
  int stage = 0;
  double stage_power[4] = {0, 0, 0, 0};
  explicit Run(const MujocoModel::Impl& m) : model(m), d(mj_makeData(m.m)) {
    if (!d) throw models::NumericalError("MuJoCo could not allocate its data");
  }
  ~Run() {
    if (current_run == this) current_run = nullptr;
    mj_deleteData(d);
  }

  double joint_q(int j) const {
    if (const auto& f = model.joint_fold[j]) return f->ratio * joint_q(f->driver_joint) + f->q_offset;
    return d->qpos[model.joint_qadr[j]];
  }
  double joint_u(int j) const {
    if (const auto& f = model.joint_fold[j]) return f->ratio * joint_u(f->driver_joint);
    return d->qvel[model.joint_dof[j]];
  }
  // Angular rate about z [rad/s]: MuJoCo's cvel holds the world angular velocity first.
  double body_rate(int b) const {
    if (const auto& f = model.body_fold[b]) return f->ratio * joint_u(f->driver_joint);
    return d->cvel[6 * model.body_id[b] + 2];
  }
  // Generalized force on a joint's coordinate; a folded joint's goes to its driver by virtual
  // power (τ_driver = r·τ_driven), as engine/scene_loads.cpp add_joint_force.
  void add_joint_force(int j, double tau) {
    if (const auto& f = model.joint_fold[j]) return add_joint_force(f->driver_joint, f->ratio * tau);
    d->qfrc_applied[model.joint_dof[j]] += tau;
  }
  models::Vec2 world_point(int body, models::Vec2 p) const {
    if (body == 0) return p;
    const double* R = d->xmat + 9 * body;
    const double* o = d->xpos + 3 * body;
    return {o[0] + R[0] * p.x + R[1] * p.y, o[1] + R[3] * p.x + R[4] * p.y};
  }
  // Velocity of a world point p fixed to a body [m/s]: the body origin's velocity (MuJoCo's
  // mj_objectVelocity, world frame) plus ω × (p − origin).
  models::Vec2 world_velocity(int body, models::Vec2 p) const {
    if (body == 0) return {0, 0};
    mjtNum v[6];
    mj_objectVelocity(model.m, d, mjOBJ_XBODY, body, v, 0);  // XBODY: at the body frame's origin (xpos)
    const double* o = d->xpos + 3 * body;
    return {v[3] - v[2] * (p.y - o[1]), v[4] + v[2] * (p.x - o[0])};
  }
  // A force at a world point of a body, as MuJoCo's Cartesian perturbation at the centre of mass,
  // so that mj_rnePostConstraint counts it in cfrc_ext (and the joint reactions stay right).
  void add_point_force(int body, models::Vec2 p, models::Vec2 f) {
    if (body == 0) return;
    double* x = d->xfrc_applied + 6 * body;
    const double* c = d->xipos + 3 * body;
    x[0] += f.x;
    x[1] += f.y;
    x[5] += (p.x - c[0]) * f.y - (p.y - c[1]) * f.x;
  }

  // The scene's loads at the current state (engine/scene_loads.cpp, kLoadsInstant: gates from the
  // sign of the rate now). Gravity is MuJoCo's own. Returns the non-conservative power [W].
  double apply_loads() {
    const auto& sc = model.scene;
    const auto& m = model.m;
    std::fill(d->qfrc_applied, d->qfrc_applied + m->nv, 0.0);
    std::fill(d->xfrc_applied, d->xfrc_applied + 6 * m->nbody, 0.0);
    double P = 0.0;
    for (const auto& t : sc.joint_torques) {
      if (t.active_when && !models::gate_open(t.active_when->sign, joint_u(sc.joint_index(t.active_when->joint)))) continue;
      const int j = sc.joint_index(t.joint);
      // value·τ(θ_of) for a profiled load (models::calc_joint_torque), value otherwise.
      const double tau = models::calc_joint_torque(t, t.profile ? joint_q(sc.joint_index(t.profile->of)) : 0.0);
      add_joint_force(j, tau);
      P += tau * joint_u(j);
    }
    for (const auto& mo : sc.motors) {
      const int j = sc.joint_index(mo.joint);
      const double u = joint_u(j), tau = models::motor_torque(mo.stall_torque, mo.no_load_speed, u);
      add_joint_force(j, tau);
      P += tau * u;
    }
    for (const auto& r : sc.resistances) {
      const int b = sc.body_index(r.body);
      const double w = body_rate(b), T = models::resistance_torque(r.law, r.coefficient, w);
      if (model.body_fold[b]) {
        add_joint_force(model.body_fold[b]->driven_joint, T);
      } else {
        d->xfrc_applied[6 * model.body_id[b] + 5] += T;
      }
      P += T * w;
    }
    // Point forces (engine/scene_loads.cpp): tension T·e on A, −T·e on B (e from A to B); power −T·L̇.
    for (const auto& f : sc.point_forces) {
      if (f.active_when && !models::gate_open(f.active_when->sign, joint_u(sc.joint_index(f.active_when->joint)))) continue;
      const int a = model.body_of(f.body_a), b = model.body_of(f.body_b);
      const auto pa = world_point(a, f.point_a), pb = world_point(b, f.point_b);
      const double dx = pb.x - pa.x, dy = pb.y - pa.y, L = std::hypot(dx, dy);
      if (!(L >= models::limits::kMinPointForceLength_m))
        throw models::NumericalError(fmt::format("MuJoCo: point force '{}': its points met at t = {:.6g} s, where the "
                                                 "line of action has no direction",
                                                 f.name, d->time));
      const double T =
          models::calc_point_force_tension(f, f.profile ? joint_q(sc.joint_index(f.profile->of)) : 0.0);
      const double ex = dx / L, ey = dy / L;
      add_point_force(a, pa, {T * ex, T * ey});
      add_point_force(b, pb, {-T * ex, -T * ey});
      const auto va = world_velocity(a, pa), vb = world_velocity(b, pb);
      P -= T * (ex * (vb.x - va.x) + ey * (vb.y - va.y));
    }
    for (const auto& sp : sc.springs) {
      const int a = model.body_of(sp.body_a), b = model.body_of(sp.body_b);
      const auto pa = world_point(a, sp.point_a), pb = world_point(b, sp.point_b);
      const double dx = pb.x - pa.x, dy = pb.y - pa.y, L = std::hypot(dx, dy);
      if (L < 1e-15) continue;
      const double k = -sp.stiffness_N_per_m * (L - sp.rest_length_m) / L;  // f_on_b = k·(pb − pa)
      add_point_force(b, pb, {k * dx, k * dy});
      add_point_force(a, pa, {-k * dx, -k * dy});
    }
    return P;
  }

  // Kinetic (½ uᵀ M u) plus potential energy (gravity −Σ m g·c, springs ½ k (L − L0)²) [J].
  double energy() const {
    const auto& sc = model.scene;
    const mjModel* m = model.m;
    std::vector<double> Mu(m->nv);
    mj_mulM(m, d, Mu.data(), d->qvel);
    double E = 0.0;
    for (int i = 0; i < m->nv; ++i) E += 0.5 * d->qvel[i] * Mu[i];
    for (int b = 1; b < m->nbody; ++b)
      E -= m->body_mass[b] * (m->opt.gravity[0] * d->xipos[3 * b] + m->opt.gravity[1] * d->xipos[3 * b + 1]);
    for (const auto& sp : sc.springs) {
      const auto pa = world_point(model.body_of(sp.body_a), sp.point_a);
      const auto pb = world_point(model.body_of(sp.body_b), sp.point_b);
      E += 0.5 * sp.stiffness_N_per_m * std::pow(std::hypot(pb.x - pa.x, pb.y - pa.y) - sp.rest_length_m, 2);
    }
    return E;
  }

  double worst_loop_gap() const {
    double worst = 0.0;
    for (const auto& l : model.scene.loops) {
      const auto pa = world_point(model.body_of(l.body_a), l.point_a);
      const auto pb = world_point(model.body_of(l.body_b), l.point_b);
      worst = std::max(worst, std::hypot(pb.x - pa.x, pb.y - pa.y));
    }
    return worst;
  }

  // Requested constraint forces [N] after mj_forward: the force part of the child's cfrc_int is
  // the force its parent exerts through the joint (Newton on the child's subtree: inertial forces
  // minus gravity minus cfrc_ext, which holds our xfrc_applied and the equality forces).
  std::vector<double> constraint_forces() {
    mj_rnePostConstraint(model.m, d);
    std::vector<double> out;
    for (size_t k = 0; k < model.request_body.size(); ++k) {
      const int b = model.request_body[k];
      const double* R = d->xmat + 9 * b;
      const auto& u = model.request_dir[k];
      const double dx = R[0] * u.x + R[1] * u.y, dy = R[3] * u.x + R[4] * u.y;
      out.push_back(d->cfrc_int[6 * b + 3] * dx + d->cfrc_int[6 * b + 4] * dy);
    }
    return out;
  }
};

void apply_loads_callback(const mjModel*, mjData* d) {
  Run* run = current_run;
  if (!run || run->d != d) return;
  const double P = run->apply_loads();
  if (run->stage < 4) run->stage_power[run->stage] = P;
  ++run->stage;
}

}  // namespace

MujocoModel::MujocoModel(const models::Scene& scene, const std::vector<double>& initial_q,
                         const MujocoSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  check_settings(settings);
  install_handlers();
  auto& im = *impl_;
  im.scene = scene;
  im.settings = settings;
  models::MjcfOptions mo;
  mo.reference_q = initial_q;
  mo.fold_geared_bodies = true;
  mo.visual_geoms = false;  // nothing to draw in timed runs
  mo.timestep_s = settings.timestep_s;
  mo.integrator = settings.integrator == "rk4" ? "RK4" : "Euler";
  mo.timeconst_s = settings.timeconst_s;
  mo.impedance = settings.impedance;
  try {
    im.mjcf = models::export_mjcf(scene, mo);
  } catch (const models::SceneError& e) {
    throw EngineError(std::string("MuJoCo peer: ") + e.what());
  }
  im.m = load_from_memory(im.mjcf);

  const size_t nj = scene.joints.size(), nb = scene.bodies.size();
  im.joint_qadr.assign(nj, -1);
  im.joint_dof.assign(nj, -1);
  im.joint_fold.resize(nj);
  im.body_id.assign(nb, -1);
  im.body_fold.resize(nb);
  for (const auto& f : models::calc_gear_folds(scene)) {
    im.joint_fold[f.driven_joint] = f;
    im.body_fold[f.body] = f;
  }
  for (size_t j = 0; j < nj; ++j) {
    if (im.joint_fold[j]) continue;
    const int id = mj_name2id(im.m, mjOBJ_JOINT, scene.joints[j].name.c_str());
    const int b = mj_name2id(im.m, mjOBJ_BODY, scene.joints[j].child.c_str());
    if (id < 0 || b < 0) throw EngineError("MuJoCo peer: joint '" + scene.joints[j].name + "' missing from the model");
    im.joint_qadr[j] = im.m->jnt_qposadr[id];
    im.joint_dof[j] = im.m->jnt_dofadr[id];
    im.body_id[scene.body_index(scene.joints[j].child)] = b;
  }
  im.independent = scene.joint_index(scene.independent);
  for (const auto& c : scene.outputs.constraint_forces) {
    const int j = scene.joint_index(c.joint);
    if (j < 0 || im.joint_fold[j]) throw EngineError("MuJoCo peer: constraint force '" + c.name + "' on no built joint");
    const double n = std::hypot(c.direction.x, c.direction.y);
    im.request_body.push_back(im.body_id[scene.body_index(scene.joints[j].child)]);
    im.request_dir.push_back({c.direction.x / n, c.direction.y / n});
  }
}

MujocoModel::~MujocoModel() = default;
const MujocoSettings& MujocoModel::settings() const { return impl_->settings; }
const std::string& MujocoModel::mjcf() const { return impl_->mjcf; }

models::TimeSeries simulate_mujoco(const MujocoModel& model, const MujocoRunOptions& opt) {
  const auto& im = model.impl();
  const mjModel* m = im.m;
  const double h = m->opt.timestep;
  auto bad = [](const std::string& what) { throw EngineError("MuJoCo peer: " + what); };
  if (!(std::isfinite(opt.duration_s) && opt.duration_s > 0)) bad(fmt::format("duration {} s must be > 0", opt.duration_s));
  if (!(std::isfinite(opt.output_interval_s) && opt.output_interval_s > 0 && opt.output_interval_s <= opt.duration_s))
    bad(fmt::format("output interval {} s must be in (0, duration]", opt.output_interval_s));
  const double per_output = opt.output_interval_s / h;
  const long steps_per_output = std::lround(per_output);
  if (steps_per_output < 1 || std::abs(per_output - steps_per_output) > 1e-6 * per_output)
    bad(fmt::format("output interval {:g} s is not a whole number of {:g} s steps (calc_peer_step)",
                    opt.output_interval_s, h));
  const long outputs = std::lround(std::floor(opt.duration_s / opt.output_interval_s + 1e-9));
  if (static_cast<double>(outputs) * steps_per_output > static_cast<double>(opt.max_steps))
    throw models::NumericalError(fmt::format("MuJoCo peer: {:g} s at {:g} s steps needs {} steps, more than the budget "
                                             "of {}",
                                             opt.duration_s, h, outputs * steps_per_output, opt.max_steps));
  if (opt.initial_u.size() != im.scene.joints.size())
    bad(fmt::format("{} initial rates for {} joints", opt.initial_u.size(), im.scene.joints.size()));
  const bool rk4 = model.settings().integrator == "rk4";

  const auto start = std::chrono::steady_clock::now();
  Run run(im);
  current_run = &run;
  mjData* d = run.d;
  for (size_t j = 0; j < im.scene.joints.size(); ++j)
    if (im.joint_dof[j] >= 0) d->qvel[im.joint_dof[j]] = opt.initial_u[j];  // qpos starts at qpos0 = the refs

  models::TimeSeries ts;
  for (const auto& c : im.scene.outputs.constraint_forces) ts.force_names.push_back(c.name);
  ts.forces.resize(ts.force_names.size());
  double W = 0.0;  // work of the non-conservative loads [J]
  auto record = [&] {
    const double t = d->time;
    ts.t.push_back(t);
    ts.q.push_back(run.joint_q(im.independent));
    ts.qdot.push_back(run.joint_u(im.independent));
    ts.qddot.push_back(d->qacc[im.joint_dof[im.independent]]);
    ts.energy.push_back(run.energy());
    ts.work.push_back(W);
    // Gates as the full model records them (bit g: rate-gated load g on), so comparisons can
    // leave out the samples where the two engines have switched at different instants.
    std::uint32_t mask = 0;
    int g = 0;
    for (const auto& t : im.scene.joint_torques) {
      if (!t.active_when) continue;
      if (g < 32 && models::gate_open(t.active_when->sign, run.joint_u(im.scene.joint_index(t.active_when->joint)))) mask |= 1u << g;
      ++g;
    }
    for (const auto& f : im.scene.point_forces) {  // after the torques, as the full model's slots
      if (!f.active_when) continue;
      if (g < 32 && models::gate_open(f.active_when->sign, run.joint_u(im.scene.joint_index(f.active_when->joint)))) mask |= 1u << g;
      ++g;
    }
    ts.gates.push_back(mask);
    const auto f = run.constraint_forces();
    for (size_t k = 0; k < f.size(); ++k) ts.forces[k].push_back(f[k]);
    ts.stats.max_constraint_error = std::max(ts.stats.max_constraint_error, run.worst_loop_gap());
    bool finite = std::isfinite(ts.q.back()) && std::isfinite(ts.qdot.back()) && std::isfinite(ts.qddot.back()) &&
                  std::isfinite(ts.energy.back());
    for (double x : f) finite &= std::isfinite(x);
    if (!finite || d->warning[mjWARN_BADQACC].number > 0)
      throw models::NumericalError(fmt::format("MuJoCo ({} at {:g} s) produced a non-finite motion at t = {:.6g} s",
                                               model.settings().integrator, h, t));
  };
  // One step: MuJoCo's forward dynamics at the step's start (loads by the callback, stage 1),
  // then the integrator, whose RK4 evaluates stages 2–4 (the callback again).
  auto step = [&](bool output) {
    run.stage = 0;
    mj_forward(m, d);
    if (output) record();
    if (rk4) {
      mj_RungeKutta(m, d, 4);
    } else {
      mj_Euler(m, d);
    }
    const auto& P = run.stage_power;
    W += rk4 ? h * (P[0] + 2 * P[1] + 2 * P[2] + P[3]) / 6 : h * P[0];
  };
  try {
    for (long i = 0; i < outputs; ++i) {
      for (long k = 0; k < steps_per_output; ++k) step(k == 0);
      d->time = (i + 1) * opt.output_interval_s;  // no drift from summing steps
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (wall > opt.max_wall_s)
        throw models::NumericalError(fmt::format("MuJoCo stopped at t = {:.6g} s: wall-time budget of {:g} s exhausted",
                                                 d->time, opt.max_wall_s));
    }
    run.stage = 4;  // the last row's evaluation is not a step: its power is not integrated
    mj_forward(m, d);
    record();
  } catch (...) {
    current_run = nullptr;
    throw;
  }
  current_run = nullptr;
  ts.stats.steps_taken = ts.stats.steps_attempted = outputs * steps_per_output;
  ts.stats.smallest_step_s = h;
  ts.stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ts;
}

#endif

}  // namespace rdyn::engine
