#include "engine/forward_dynamics.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "engine/branch_guard.hpp"
#include "engine/full_model_impl.hpp"
#include "engine/independent_range.hpp"
#include "engine/kinetostatic.hpp"
#include "engine/singular_passage.hpp"
#include "reduced/joint_outputs.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

std::unique_ptr<Integrator> make_integrator(const FullModel::Impl& m, const std::string& name) {
  if (name == "rkmerson") return std::make_unique<RungeKuttaMersonIntegrator>(m.system);
  if (name == "rk3") return std::make_unique<RungeKutta3Integrator>(m.system);
  if (name == "cpodes") return std::make_unique<CPodesIntegrator>(m.system);
  throw EngineError("unknown integrator '" + name + "' (rkmerson, rk3, cpodes)");
}

// Gate flags at the start: from the sign of the gating rate; from rest, from the sign of
// the acceleration the load would produce (switched on, it must push the right way).
void initialize_gates(const FullModel::Impl& m, State& s) {
  const auto& sc = m.scene;
  for (size_t i = 0; i < num_load_slots(sc); ++i) {
    const auto* gate = load_gate(sc, i);
    if (!gate) continue;
    const int j = sc.joint_index(gate->joint);
    m.system.realize(s, Stage::Velocity);
    const double rate = m.joint_u(s, j);
    if (std::abs(rate) > 1e-12) {
      m.set_gate(s, static_cast<int>(i), models::gate_open(gate->sign, rate));
      continue;
    }
    m.set_gate(s, static_cast<int>(i), true);
    m.system.realize(s, Stage::Acceleration);
    const auto& mb = m.joint_mobod[j];
    const double acc = m.joint_fold[j] ? 0.0 : mb.getOneUDot(s, MobilizerUIndex(0));
    m.set_gate(s, static_cast<int>(i), models::gate_open(gate->sign, acc));
  }
}

void record(const FullModel::Impl& m, const State& s, TimeSeries& ts) {
  m.system.realize(s, Stage::Acceleration);
  const auto& mb = m.joint_mobod[m.independent];
  ts.t.push_back(s.getTime());
  ts.q.push_back(mb.getOneQ(s, MobilizerQIndex(0)));
  ts.qdot.push_back(mb.getOneU(s, MobilizerUIndex(0)));
  ts.qddot.push_back(mb.getOneUDot(s, MobilizerUIndex(0)));
  ts.energy.push_back(m.system.calcEnergy(s));
  ts.work.push_back(m.work(s));
  std::uint32_t mask = 0;
  for (size_t i = 0, g = 0; i < num_load_slots(m.scene); ++i)
    if (load_gate(m.scene, i)) {
      if (m.gate(s, static_cast<int>(i)) && g < 32) mask |= 1u << g;
      ++g;
    }
  ts.gates.push_back(mask);
  const auto f = m.constraint_forces(s);
  for (size_t k = 0; k < f.size(); ++k) ts.forces[k].push_back(f[k]);
  if (!ts.columns.empty()) {
    std::vector<double> c;
    calc_joint_outputs(m, s, c);
    for (size_t k = 0; k < c.size(); ++k) ts.columns[k].push_back(c[k]);
  }
  ts.stats.max_constraint_error = std::max(ts.stats.max_constraint_error, m.worst_loop_gap(s).first);
}

// The Simbody state of free motion at p on the branch the guard follows (its workspace at p.q):
// a kinetostatic projection at (q, q̇), then the independent coordinate released. The start of
// a run, and the restart after a singular passage.
State free_state(const FullModel& model, BranchGuard& guard, const PassagePoint& p) {
  const auto& m = model.impl();
  calc_kinetostatic(model, guard.ws, p.q, p.qdot, 0.0, Loads::Off);
  State s = guard.ws.impl().state;
  m.independent_motion.disable(s);
  m.system.realizeModel(s);
  s.setTime(p.t);
  m.set_load_mode(s, kLoadsEvents);
  m.set_work(s, p.work);
  Value<long>::updDowncast(m.forces.updDiscreteVariable(s, m.indices->events)) = 0;
  initialize_gates(m, s);
  return s;
}

// Replaces the last rows, one per node of the stencil, by their interpolation at its point
// (singular_passage.hpp); gates from the node nearest below it.
void combine_last_rows(TimeSeries& ts, const LimitStencil& st) {
  const size_t k = st.w.size();
  auto combine = [&](std::vector<double>& v) {
    const size_t first = v.size() - k;
    double r = 0.0;
    for (size_t i = 0; i < k; ++i) r += st.w[i] * v[first + i];
    v.resize(first + 1);
    v.back() = r;
  };
  for (auto* v : {&ts.t, &ts.q, &ts.qdot, &ts.qddot, &ts.energy, &ts.work}) combine(*v);
  for (auto& v : ts.forces) combine(v);
  for (auto& v : ts.columns) combine(v);
  const auto g = ts.gates[ts.gates.size() - k + k / 2 - 1];
  ts.gates.resize(ts.gates.size() - k + 1);
  ts.gates.back() = g;
}

// One output row of a singular passage at p: the full state on the branch with the free
// acceleration prescribed (the drive it needs is then zero), recorded as the integrator's rows
// are. Near rank loss q̈ comes from the limit stencil, but the row — its constraint forces and
// reactions above all — is taken at p itself: those forces can grow without bound toward the
// flat configuration (a loss-torque's share ~τ/(2 sin q) in a parallelogram), which an
// interpolation from outside the limit radius misses (−33 N for −41 N at 0.013 rad from a
// 3-loop chain's flat position). Only where the rates are not determined at all
// (κ < kSingularConditioning, ~1e-4 rad from it) is the row the stencil's interpolation.
// Returns the kinetic energy (of the row, or the largest of the stencil's) [J].
double record_passage(const FullModel& model, BranchGuard& guard, const IndependentDomain& domain,
                      const PassagePoint& p, TimeSeries& ts) {
  const auto& m = model.impl();
  double kinetic_J = 0.0;
  auto row_at = [&](double q, const LimitStencil& stencil) {
    const auto fm = calc_free_motion(model, guard, q, p.qdot, stencil);
    const double k = set_passage_state(model, guard, q, p.qdot, fm.qddot);
    State& st = guard.ws.impl().state;  // its time stays 0: the prescribed law is q + q̇ t + ½ q̈ t²
    m.set_work(st, p.work);
    initialize_gates(m, st);
    record(m, st, ts);
    ts.t.back() = p.t;
    kinetic_J = std::max(kinetic_J, m.system.calcKineticEnergy(st));
    return k;
  };
  const auto stencil = limit_stencil_at(domain.singular, domain.periodic, p.q);
  if (row_at(p.q, stencil) >= kSingularConditioning) return kinetic_J;
  for (auto* v : {&ts.t, &ts.q, &ts.qdot, &ts.qddot, &ts.energy, &ts.work}) v->pop_back();
  for (auto& v : ts.forces) v.pop_back();
  for (auto& v : ts.columns) v.pop_back();
  ts.gates.pop_back();
  kinetic_J = 0.0;
  for (const double x : stencil.x) row_at(x, LimitStencil{});
  combine_last_rows(ts, stencil);
  ++ts.stats.interpolated_rows;
  ts.t.back() = p.t, ts.q.back() = p.q, ts.qdot.back() = p.qdot, ts.work.back() = p.work;
  follow_branch(model, guard.ws, p.q, guard.max_move, guard.max_correction);
  return kinetic_J;
}

// Options in their documented ranges (EngineError: they are input, from the scene or the CLI).
void check_options(const ForwardOptions& opt) {
  auto bad = [](const std::string& what) { throw EngineError("forward dynamics: " + what); };
  if (!(std::isfinite(opt.duration_s) && opt.duration_s > 0))
    bad(fmt::format("duration {} s must be positive and finite", opt.duration_s));
  if (!(std::isfinite(opt.output_interval_s) && opt.output_interval_s > 0))
    bad(fmt::format("output interval {} s must be positive and finite", opt.output_interval_s));
  if (opt.duration_s / opt.output_interval_s + 1 > static_cast<double>(kMaxOutputRows))
    bad(fmt::format("output interval {:g} s over {:g} s gives {:.3g} rows, more than {:g}; use an interval of at "
                    "least {:.3g} s",
                    opt.output_interval_s, opt.duration_s, opt.duration_s / opt.output_interval_s + 1,
                    static_cast<double>(kMaxOutputRows), opt.duration_s / (kMaxOutputRows - 1)));
  if (!(opt.tolerance > 0 && opt.tolerance <= 1))
    bad(fmt::format("tolerance {} must be in (0, 1]", opt.tolerance));
  if (opt.integrator != "rkmerson" && opt.integrator != "rk3" && opt.integrator != "cpodes")
    bad("unknown integrator '" + opt.integrator + "' (rkmerson, rk3, cpodes)");
  if (!(opt.max_steps > 0)) bad(fmt::format("step budget {} must be positive", opt.max_steps));
  if (!(std::isfinite(opt.max_wall_s) && opt.max_wall_s > 0))
    bad(fmt::format("wall-time budget {} s must be positive and finite", opt.max_wall_s));
  if (!(std::isfinite(opt.energy_tolerance) && opt.energy_tolerance > 0))
    bad(fmt::format("energy tolerance {} must be positive and finite", opt.energy_tolerance));
}

// The last recorded row, every value finite (Simbody can return NaN/inf without throwing,
// e.g. after an overflow of a runaway speed).
void check_finite_row(const TimeSeries& ts) {
  const double t = ts.t.back();
  auto check = [t](double v, const std::string& what) {
    if (!std::isfinite(v))
      throw models::NumericalError(fmt::format("full model produced a non-finite {} at t = {:.6g} s", what, t));
  };
  check(ts.q.back(), "coordinate");
  check(ts.qdot.back(), "speed");
  check(ts.qddot.back(), "acceleration");
  check(ts.energy.back(), "energy");
  check(ts.work.back(), "work");
  for (size_t k = 0; k < ts.forces.size(); ++k)
    check(ts.forces[k].back(), "constraint force '" + ts.force_names[k] + "'");
  for (size_t k = 0; k < ts.columns.size(); ++k) check(ts.columns[k].back(), "output '" + ts.column_names[k] + "'");
}

// A point force's line may not pass through zero length: there its direction is undefined (and
// a muscle's attachments cannot cross). Exactly zero is caught where the force is applied; a
// crossing between two evaluations shows as the line reversing within one step (e turning by
// more than 90°, which no accurate step of a smooth motion does). e_prev: each line's direction
// after the previous step.
void check_point_force_lines(const FullModel::Impl& m, const State& s, std::vector<Vec3>& e_prev) {
  const auto& pf = m.scene.point_forces;
  for (size_t i = 0; i < pf.size(); ++i) {
    const auto line = calc_point_force_line(m, s, pf[i], false);
    if (!(line.length >= models::limits::kMinPointForceLength_m) ||
        (e_prev.size() == pf.size() && dot(e_prev[i], line.e_G) < 0))
      throw models::NumericalError(fmt::format(
          "point force '{}': its points met (the line's length reached zero and its direction reversed) near t = "
          "{:.6g} s, where the line of action has no direction; move the attachment points apart",
          pf[i].name, s.getTime()));
    if (e_prev.size() == pf.size()) e_prev[i] = line.e_G;
  }
  if (e_prev.size() != pf.size())
    for (const auto& f : pf) e_prev.push_back(calc_point_force_line(m, s, f, false).e_G);
}

// The branch guard at one output sample (engine/branch_guard.hpp): every joint of the integrated
// state on the branch the run started on, or NumericalError naming the time, the joint and both
// values. The guard failing to follow its own branch is a numerical failure too.
void check_branch(const FullModel& model, BranchGuard& guard, const State& s, double t_prev) {
  const auto& m = model.impl();
  std::vector<double> q(m.scene.joints.size());
  for (size_t j = 0; j < q.size(); ++j) q[j] = m.joint_q(s, static_cast<int>(j));
  BranchCheck c;
  try {
    c = calc_branch_check(model, guard, q[m.independent], q);
  } catch (const EngineError& e) {
    throw models::NumericalError(fmt::format("full model's branch guard could not follow the starting branch to "
                                             "t = {:.6g} s: {}",
                                             s.getTime(), e.what()));
  }
  if (!c.on_branch) throw models::NumericalError(describe_branch_switch(model, c, s.getTime(), t_prev));
}

}  // namespace

namespace {

// One forward-dynamics run: Simbody's integrator between singular passages, the passages in the
// partitioned formulation, the output rows, the budgets and the statistics. The run's own
// workspace (the model stays const); simulate_full drives it stage by stage.
class FullRun {
 public:
  FullRun(const FullModel& model, const ForwardOptions& opt)
      : model_(model), m_(model.impl()), opt_(opt), start_(std::chrono::steady_clock::now()),
        // The validity domain of the independent coordinate: a run that leaves it stops (exit
        // 1), as the reduced model stops at its table's edge (reduced/simulate_reduced.cpp).
        domain_(opt.domain ? *opt.domain : calc_independent_domain(model)), guard_(model),
        singular_(opt.singular_passages ? domain_.singular : std::vector<SingularPoint>{}),
        integ_(make_integrator(m_, opt.integrator)), stepper_(std::make_unique<TimeStepper>(m_.system, *integ_)),
        n_(models::calc_output_rows(opt.duration_s, opt.output_interval_s)) {}

  // The consistent initial state (a kinetostatic projection at (q0, q̇0) in the branch guard's
  // workspace, which then continues along the starting branch), the integrator and row 0.
  void start();
  // Rows until the run's end: Simbody up to each output time, a passage where a step touches a
  // window around a configuration of rank loss.
  void run();
  // Statistics and the run's own energy-balance check.
  TimeSeries finish();

 private:
  double wall() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  double output_time(long i) const { return models::calc_output_time(i, n_, opt_.duration_s, opt_.output_interval_s); }
  // Simbody's steps to output time t; false when a step touched a window (passage_ is then set to
  // the state before it, which was taken back).
  bool step_to(double t);
  void check_domain(double t_before, double q_before);
  void check_budgets(double h);
  void record_row();
  // The partitioned formulation from passage_ until out of the windows; Simbody restarts there.
  void cross_passage();
  void restart(const PassagePoint& end);

  const FullModel& model_;
  const FullModel::Impl& m_;
  const ForwardOptions& opt_;
  const std::chrono::steady_clock::time_point start_;
  const IndependentDomain domain_;
  BranchGuard guard_;
  const std::vector<SingularPoint> singular_;
  std::unique_ptr<Integrator> integ_;
  // Replaced with the integrator at each restart: CPodes leaks its solver's memory when
  // initialized a second time (LeakSanitizer, 340 allocations in libSimTKmath per restart).
  std::unique_ptr<TimeStepper> stepper_;
  void configure_integrator();
  const long n_;  // output rows after t = 0, the last at t = duration
  long i_ = 1;    // the next output row
  TimeSeries ts_;
  // Largest kinetic energy and |W| seen [J]: with max|E| the scale of the energy-balance test.
  // max|E| alone fails where E ≡ 0 by the choice of datum (a pendulum released from the
  // horizontal through its pivot's height): the residual is then rounding over ~0.
  double motion_scale_J_ = 0.0;
  double smallest_ = INFINITY;
  long calls_ = 0;  // stepTo calls: bounded even if a call were to return without a step
  double window_t0_ = 0.0;
  std::vector<Vec3> line_dir_;  // point forces' directions after the last step
  std::optional<PassagePoint> passage_;  // set: start the partitioned formulation here
  // Counts of the Simbody segments before the last restart, and of the passages.
  long passage_steps_ = 0, passages_ = 0, steps_before_ = 0, attempts_before_ = 0, events_before_ = 0;
};

void FullRun::configure_integrator() {
  integ_->setAccuracy(opt_.tolerance);
  integ_->setConstraintTolerance(std::min(1e-10, opt_.tolerance));
  // Return after every internal step: to track the smallest step, and so that the step and
  // wall-time budgets are checked between steps, not only between outputs.
  integ_->setReturnEveryInternalStep(true);
  // Step freely and interpolate (then project) the states at output times, rather than
  // shortening steps to land on them: the full model's cheapest honest setting.
  integ_->setAllowInterpolation(true);
  integ_->setProjectInterpolatedStates(true);
  // TimeStepper::stepTo otherwise swallows the integrator's per-step returns and comes back
  // only at the output time (Simbody 3.7 TimeStepperRep::stepTo loops until then), so a
  // single output interval of microscopic steps would never reach the budget checks below.
  stepper_->setReportAllSignificantStates(true);
}

void FullRun::start() {
  const State s = free_state(model_, guard_, {0.0, m_.scene.initial.q, m_.scene.initial.qdot, 0.0});
  configure_integrator();
  try {
    stepper_->initialize(s);
  } catch (const std::exception& e) {
    throw models::NumericalError(std::string("cannot start the full model: ") + describe_simbody_exception(e));
  }
  for (const auto& c : m_.scene.outputs.constraint_forces) ts_.force_names.push_back(c.name);
  ts_.forces.resize(ts_.force_names.size());
  ts_.column_names = reduced::joint_output_names(m_.scene);
  ts_.columns.resize(ts_.column_names.size());
  // Started inside a window (near, not at, a configuration of rank loss): the partitioned
  // formulation from the first row on (Simbody's q̈ there carried the projection's error: 1.9
  // rad/s² where it is 0, a 3-loop chain 1e-4 rad from flat at 300 rad/s).
  if (!singular_.empty() && !outside_windows(singular_, domain_.periodic, m_.scene.initial.q))
    passage_ = PassagePoint{0.0, m_.scene.initial.q, m_.scene.initial.qdot, 0.0};
  if (passage_) {
    motion_scale_J_ = record_passage(model_, guard_, domain_, *passage_, ts_);
  } else {
    record(m_, integ_->getState(), ts_);
    motion_scale_J_ = m_.system.calcKineticEnergy(integ_->getState());
  }
  check_finite_row(ts_);
  m_.system.realize(integ_->getState(), Stage::Position);
  check_point_force_lines(m_, integ_->getState(), line_dir_);
}

void FullRun::run() {
  while (i_ <= n_) {
    if (passage_) {
      cross_passage();
      continue;
    }
    if (!step_to(output_time(i_))) continue;
    record_row();
    ++i_;
  }
}

bool FullRun::step_to(double t) {
  try {
    while (integ_->getTime() < t - 1e-14) {
      const double t_before = integ_->getTime(), q_before = m_.joint_q(integ_->getState(), m_.independent);
      std::optional<State> before;
      if (!singular_.empty()) before = integ_->getState();
      stepper_->stepTo(t);
      if (before) {
        const double q_adv = m_.joint_q(integ_->getAdvancedState(), m_.independent);
        if (find_window(singular_, domain_.periodic, q_before, q_adv) >= 0) {
          passage_ = PassagePoint{t_before, q_before, m_.joint_u(*before, m_.independent), m_.work(*before)};
          return false;
        }
      }
      const double h = integ_->getPreviousStepSizeTaken();
      if (!line_dir_.empty()) check_point_force_lines(m_, integ_->getState(), line_dir_);
      check_domain(t_before, q_before);
      if (h > 0) smallest_ = std::min(smallest_, h);
      check_budgets(h);
    }
  } catch (const models::NumericalError&) {
    throw;
  } catch (const std::exception& e) {
    // Simbody turns a force's refusal (a point force at zero length) into failed steps: name
    // the point force when that is where the integrator got stuck.
    if (!line_dir_.empty()) {
      State last = integ_->getState();
      m_.system.realize(last, Stage::Position);
      check_point_force_lines(m_, last, line_dir_);
    }
    throw models::NumericalError(fmt::format("full model failed at t = {:.6g} s (last step {:.3g} s): {}",
                                             integ_->getTime(), integ_->getPreviousStepSizeTaken(),
                                             describe_simbody_exception(e)));
  }
  return true;
}

void FullRun::check_domain(double t_before, double q_before) {
  if (domain_.periodic) return;
  const double q_now = m_.joint_q(integ_->getState(), m_.independent);
  if (!(q_now < domain_.min || q_now > domain_.max)) return;
  // Crossing time by linear interpolation inside the step (for the message only).
  const bool low = q_now < domain_.min;
  const double edge = low ? domain_.min : domain_.max;
  const double t_cross = t_before + (integ_->getTime() - t_before) * (edge - q_before) / (q_now - q_before);
  throw models::NumericalError(fmt::format("full model left the validity domain at {} ({}) at t = {:.6g} s",
                                           format_coordinate(edge, domain_.revolute),
                                           low ? domain_.min_edge : domain_.max_edge, t_cross));
}

void FullRun::check_budgets(double h) {
  // Hopeless runs fail early: every kWindow steps, the steps still needed at the window's
  // mean step size; more than kHopeless budgets (a margin for start-up transients and event
  // localization, which shrink steps for a while) will not finish, so stop now instead of
  // after the wall-time budget (a c1 = 1e9 N·m·s resistance: 600 s → < 1 s, measured).
  constexpr long kWindow = 1000;
  constexpr double kHopeless = 100.0;
  const long steps = std::max<long>(++calls_, attempts_before_ + integ_->getNumStepsAttempted()) + passage_steps_;
  const double w = wall();
  if (calls_ % kWindow == 0) {
    const double now = integ_->getTime(), mean_h = (now - window_t0_) / kWindow;
    const double needed = steps + (opt_.duration_s - now) / std::max(mean_h, 1e-300);
    window_t0_ = now;
    if (needed > kHopeless * static_cast<double>(opt_.max_steps))
      throw models::NumericalError(fmt::format(
          "full model stopped at t = {:.6g} s of {:.6g} s: at its mean step of the last {} steps ({:.3g} s) it "
          "would need ~{:.3g} steps, more than {:g} × the step budget of {}: the motion is too stiff or too fast for "
          "'{}' at tolerance {:g}",
          now, opt_.duration_s, kWindow, mean_h, needed, kHopeless, opt_.max_steps, opt_.integrator, opt_.tolerance));
  }
  if (steps > opt_.max_steps || w > opt_.max_wall_s || !std::isfinite(integ_->getTime()))
    throw models::NumericalError(fmt::format(
        "full model stopped at t = {:.6g} s of {:.6g} s: {} (last step {:.3g} s, smallest {:.3g} s): the motion is "
        "too stiff or too fast for '{}' at tolerance {:g}",
        integ_->getTime(), opt_.duration_s,
        steps > opt_.max_steps ? fmt::format("step budget of {} steps exhausted", opt_.max_steps)
                               : fmt::format("wall-time budget of {:g} s exhausted", opt_.max_wall_s),
        h, std::isfinite(smallest_) ? smallest_ : 0.0, opt_.integrator, opt_.tolerance));
}

void FullRun::record_row() {
  record(m_, integ_->getState(), ts_);
  check_finite_row(ts_);
  if (opt_.branch_guard) check_branch(model_, guard_, integ_->getState(), ts_.t[ts_.t.size() - 2]);
  motion_scale_J_ = std::max(
      {motion_scale_J_, m_.system.calcKineticEnergy(integ_->getState()), std::abs(ts_.work.back())});
}

void FullRun::cross_passage() {
  PassageOptions po;
  po.tolerance = opt_.tolerance;
  po.t_end = opt_.duration_s;
  po.max_steps = std::max(1L, opt_.max_steps - passage_steps_ - attempts_before_ - integ_->getNumStepsAttempted());
  po.max_wall_s = std::max(0.0, opt_.max_wall_s - wall());
  long taken = 0;
  PassagePoint end;
  try {
    end = integrate_passage(
        model_, guard_, singular_, domain_.periodic, *passage_, po,
        [&] { return i_ <= n_ ? output_time(i_) : INFINITY; },
        [&](const PassagePoint& p) {
          const double kinetic_J = record_passage(model_, guard_, domain_, p, ts_);
          check_finite_row(ts_);
          motion_scale_J_ = std::max({motion_scale_J_, kinetic_J, std::abs(ts_.work.back())});
          ++i_;
        },
        taken);
  } catch (const EngineError& e) {  // the continuation failed: numerical, not the input
    throw models::NumericalError(
        fmt::format("full model's singular passage from t = {:.6g} s failed: {}", passage_->t, e.what()));
  }
  passage_steps_ += taken;
  ++passages_;
  passage_.reset();
  if (i_ <= n_) restart(end);
}

void FullRun::restart(const PassagePoint& end) {
  steps_before_ += integ_->getNumStepsTaken();
  attempts_before_ += integ_->getNumStepsAttempted();
  events_before_ += m_.events(integ_->getState());
  try {
    stepper_.reset();
    integ_ = make_integrator(m_, opt_.integrator);
    stepper_ = std::make_unique<TimeStepper>(m_.system, *integ_);
    configure_integrator();
    stepper_->initialize(free_state(model_, guard_, end));  // EngineError too: caught below
  } catch (const std::exception& e) {
    throw models::NumericalError(fmt::format("full model could not restart after the singular passage at t = "
                                             "{:.6g} s: {}",
                                             end.t, describe_simbody_exception(e)));
  }
  line_dir_.clear();
  m_.system.realize(integ_->getState(), Stage::Position);
  check_point_force_lines(m_, integ_->getState(), line_dir_);
}

TimeSeries FullRun::finish() {
  ts_.stats.steps_taken = steps_before_ + integ_->getNumStepsTaken() + passage_steps_;
  ts_.stats.steps_attempted = attempts_before_ + integ_->getNumStepsAttempted() + passage_steps_;
  ts_.stats.singular_passages = passages_;
  ts_.stats.events = events_before_ + m_.events(integ_->getState());
  ts_.stats.smallest_step_s = std::isfinite(smallest_) ? smallest_ : 0.0;
  ts_.stats.wall_time_s = wall();
  // The run checks itself: E(t) − E(0) = W(t) must hold to a fraction of the energy.
  const auto eb = models::energy_balance(ts_);
  const double scale_J = std::max(eb.energy_scale_J, motion_scale_J_);
  if (!(eb.max_residual_J <= opt_.energy_tolerance * scale_J + kEnergyFloor_J))
    throw models::NumericalError(fmt::format(
        "full model's energy balance does not close: max|E − E0 − W| = {:.3g} J at t = {:.6g} s is {:.3g} % of the "
        "energy scale {:.3g} J (largest |E|, kinetic energy or |W|; limit {:g} %): the integration lost or invented "
        "energy ('{}' at tolerance {:g}; try a tighter tolerance{})",
        eb.max_residual_J, eb.worst_time_s, 100 * eb.max_residual_J / std::max(scale_J, kEnergyFloor_J), scale_J,
        100 * opt_.energy_tolerance, opt_.integrator, opt_.tolerance, opt_.integrator == "cpodes" ? "" : " or cpodes"));
  return std::move(ts_);
}

}  // namespace

TimeSeries simulate_full(const FullModel& model, const ForwardOptions& opt) {
  check_options(opt);
  FullRun run(model, opt);
  run.start();
  run.run();
  return run.finish();
}

}  // namespace rdyn::engine
