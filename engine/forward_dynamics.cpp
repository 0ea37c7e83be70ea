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
// are; near rank loss, where the multipliers are poorly determined, the interpolation of rows
// taken outside the limit radius. Returns the kinetic
// energy (of the row, or the largest of the four) [J].
double record_passage(const FullModel& model, BranchGuard& guard, const IndependentDomain& domain,
                      const PassagePoint& p, TimeSeries& ts) {
  const auto& m = model.impl();
  double kinetic_J = 0.0;
  auto row_at = [&](double q) {
    const auto fm = calc_free_motion(model, guard, q, p.qdot, LimitStencil{});
    set_passage_state(model, guard, q, p.qdot, fm.qddot);
    State& st = guard.ws.impl().state;  // its time stays 0: the prescribed law is q + q̇ t + ½ q̈ t²
    m.set_work(st, p.work);
    initialize_gates(m, st);
    record(m, st, ts);
    ts.t.back() = p.t;
    kinetic_J = std::max(kinetic_J, m.system.calcKineticEnergy(st));
  };
  const auto stencil = limit_stencil_at(domain.singular, domain.periodic, p.q);
  if (stencil.x.empty()) {
    row_at(p.q);
    return kinetic_J;
  }
  for (const double x : stencil.x) row_at(x);
  combine_last_rows(ts, stencil);
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

TimeSeries simulate_full(const FullModel& model, const ForwardOptions& opt) {
  const auto& m = model.impl();
  check_options(opt);
  const auto start = std::chrono::steady_clock::now();
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

  // The validity domain of the independent coordinate: a run that leaves it stops (exit 1),
  // as the reduced model stops at its table's edge (reduced/simulate_reduced.cpp).
  const IndependentDomain domain = opt.domain ? *opt.domain : calc_independent_domain(model);

  // Consistent initial state: a kinetostatic projection at (q0, q̇0), then the independent
  // coordinate is released.
  // The workspace then stays with the branch guard, which continues it along the starting branch.
  BranchGuard guard(model);
  State s = free_state(model, guard, {0.0, m.scene.initial.q, m.scene.initial.qdot, 0.0});

  auto integ = make_integrator(m, opt.integrator);
  integ->setAccuracy(opt.tolerance);
  integ->setConstraintTolerance(std::min(1e-10, opt.tolerance));
  // Return after every internal step: to track the smallest step, and so that the step and
  // wall-time budgets are checked between steps, not only between outputs.
  integ->setReturnEveryInternalStep(true);
  // Step freely and interpolate (then project) the states at output times, rather than
  // shortening steps to land on them: the full model's cheapest honest setting.
  integ->setAllowInterpolation(true);
  integ->setProjectInterpolatedStates(true);
  TimeStepper stepper(m.system, *integ);
  // TimeStepper::stepTo otherwise swallows the integrator's per-step returns and comes back
  // only at the output time (Simbody 3.7 TimeStepperRep::stepTo loops until then), so a
  // single output interval of microscopic steps would never reach the budget checks below.
  stepper.setReportAllSignificantStates(true);
  try {
    stepper.initialize(s);
  } catch (const std::exception& e) {
    throw models::NumericalError(std::string("cannot start the full model: ") + describe_simbody_exception(e));
  }

  long events_before_restarts = 0;  // gate switches counted in the States of earlier Simbody segments
  TimeSeries ts;
  for (const auto& c : m.scene.outputs.constraint_forces) ts.force_names.push_back(c.name);
  ts.forces.resize(ts.force_names.size());
  ts.column_names = reduced::joint_output_names(m.scene);
  ts.columns.resize(ts.column_names.size());
  const long n = models::calc_output_rows(opt.duration_s, opt.output_interval_s);  // the last at t = duration
  record(m, integ->getState(), ts);
  check_finite_row(ts);
  // Largest kinetic energy and |W| seen [J]: with max|E| the scale of the energy-balance test.
  // max|E| alone fails where E ≡ 0 by the choice of datum (a pendulum released from the
  // horizontal through its pivot's height): the residual is then rounding over ~0.
  double motion_scale_J = m.system.calcKineticEnergy(integ->getState());
  double smallest = INFINITY;
  long calls = 0;  // stepTo calls: bounded even if a call were to return without a step
  // Hopeless runs fail early: every kWindow steps, the steps still needed at the window's
  // mean step size; more than kHopeless budgets (a margin for start-up transients and event
  // localization, which shrink steps for a while) will not finish, so stop now instead of
  // after the wall-time budget (a c1 = 1e9 N·m·s resistance: 600 s → < 1 s, measured).
  constexpr long kWindow = 1000;
  constexpr double kHopeless = 100.0;
  double window_t0 = 0.0;
  std::vector<Vec3> line_dir;  // point forces' directions after the last step
  m.system.realize(integ->getState(), Stage::Position);
  check_point_force_lines(m, integ->getState(), line_dir);
  // Singular passages (engine/singular_passage.hpp): a step that touches a window around a
  // configuration of rank loss is taken back and the window is crossed in the partitioned
  // formulation; Simbody restarts beyond it.
  const bool periodic = domain.periodic;
  static const std::vector<SingularPoint> kNone;
  const auto& singular = opt.singular_passages ? domain.singular : kNone;
  std::optional<PassagePoint> passage;  // set: start the partitioned formulation here
  if (!singular.empty() && !outside_windows(singular, periodic, m.scene.initial.q))
    passage = PassagePoint{0.0, m.scene.initial.q, m.scene.initial.qdot, 0.0};
  long passage_steps = 0, passages = 0, steps_before_restarts = 0, attempts_before_restarts = 0;
  for (long i = 1; i <= n;) {
    if (passage) {
      PassageOptions po;
      po.tolerance = opt.tolerance;
      po.t_end = opt.duration_s;
      po.max_steps = std::max(1L, opt.max_steps - passage_steps - steps_before_restarts - integ->getNumStepsAttempted());
      po.max_wall_s = std::max(0.0, opt.max_wall_s - wall());
      long taken = 0;
      PassagePoint end;
      try {
        end = integrate_passage(
          model, guard, singular, periodic, *passage, po,
          [&] { return i <= n ? models::calc_output_time(i, n, opt.duration_s, opt.output_interval_s) : INFINITY; },
          [&](const PassagePoint& p) {
            const double kinetic_J = record_passage(model, guard, domain, p, ts);
            check_finite_row(ts);
            motion_scale_J = std::max({motion_scale_J, kinetic_J, std::abs(ts.work.back())});
            ++i;
          },
          taken);
      } catch (const EngineError& e) {  // the continuation failed: numerical, not the input
        throw models::NumericalError(fmt::format("full model's singular passage from t = {:.6g} s failed: {}",
                                                 passage->t, e.what()));
      }
      passage_steps += taken;
      ++passages;
      passage.reset();
      if (i > n) break;
      // Simbody again, from the end of the passage.
      const long taken_before = integ->getNumStepsTaken(), attempted_before = integ->getNumStepsAttempted();
      events_before_restarts += m.events(integ->getState());
      try {
        stepper.initialize(free_state(model, guard, end));  // EngineError too: caught below
        if (integ->getNumStepsAttempted() < attempted_before) {  // the statistics restarted too
          steps_before_restarts += taken_before;
          attempts_before_restarts += attempted_before;
        }
      } catch (const std::exception& e) {
        throw models::NumericalError(fmt::format("full model could not restart after the singular passage at t = "
                                                 "{:.6g} s: {}",
                                                 end.t, describe_simbody_exception(e)));
      }
      line_dir.clear();
      m.system.realize(integ->getState(), Stage::Position);
      check_point_force_lines(m, integ->getState(), line_dir);
      continue;
    }
    const double t = models::calc_output_time(i, n, opt.duration_s, opt.output_interval_s);
    try {
      while (integ->getTime() < t - 1e-14) {
        const double t_before = integ->getTime(), q_before = m.joint_q(integ->getState(), m.independent);
        std::optional<State> before;
        if (!singular.empty()) before = integ->getState();
        stepper.stepTo(t);
        if (before) {
          const double q_adv = m.joint_q(integ->getAdvancedState(), m.independent);
          if (find_window(singular, periodic, q_before, q_adv) >= 0) {
            passage = PassagePoint{t_before, q_before, m.joint_u(*before, m.independent), m.work(*before)};
            break;
          }
        }
        const double h = integ->getPreviousStepSizeTaken();
        if (!line_dir.empty()) check_point_force_lines(m, integ->getState(), line_dir);
        if (!domain.periodic) {
          const double q_now = m.joint_q(integ->getState(), m.independent);
          if (q_now < domain.min || q_now > domain.max) {
            // Crossing time by linear interpolation inside the step (for the message only).
            const bool low = q_now < domain.min;
            const double edge = low ? domain.min : domain.max;
            const double t_cross = t_before + (integ->getTime() - t_before) * (edge - q_before) / (q_now - q_before);
            throw models::NumericalError(fmt::format(
                "full model left the validity domain at {} ({}) at t = {:.6g} s", format_coordinate(edge, domain.revolute),
                low ? domain.min_edge : domain.max_edge, t_cross));
          }
        }
        if (h > 0) smallest = std::min(smallest, h);
        const long steps =
            std::max<long>(++calls, attempts_before_restarts + integ->getNumStepsAttempted()) + passage_steps;
        const double w = wall();
        if (calls % kWindow == 0) {
          const double now = integ->getTime(), mean_h = (now - window_t0) / kWindow;
          const double needed = steps + (opt.duration_s - now) / std::max(mean_h, 1e-300);
          window_t0 = now;
          if (needed > kHopeless * static_cast<double>(opt.max_steps))
            throw models::NumericalError(fmt::format(
                "full model stopped at t = {:.6g} s of {:.6g} s: at its mean step of the last {} steps ({:.3g} s) "
                "it would need ~{:.3g} steps, more than {:g} × the step budget of {}: the motion is too stiff or "
                "too fast for '{}' at tolerance {:g}",
                now, opt.duration_s, kWindow, mean_h, needed, kHopeless, opt.max_steps, opt.integrator,
                opt.tolerance));
        }
        if (steps > opt.max_steps || w > opt.max_wall_s || !std::isfinite(integ->getTime()))
          throw models::NumericalError(fmt::format(
              "full model stopped at t = {:.6g} s of {:.6g} s: {} (last step {:.3g} s, smallest {:.3g} s): the "
              "motion is too stiff or too fast for '{}' at tolerance {:g}",
              integ->getTime(), opt.duration_s,
              steps > opt.max_steps ? fmt::format("step budget of {} steps exhausted", opt.max_steps)
                                    : fmt::format("wall-time budget of {:g} s exhausted", opt.max_wall_s),
              h, std::isfinite(smallest) ? smallest : 0.0, opt.integrator, opt.tolerance));
      }
    } catch (const models::NumericalError&) {
      throw;
    } catch (const std::exception& e) {
      // Simbody turns a force's refusal (a point force at zero length) into failed steps: name
      // the point force when that is where the integrator got stuck.
      if (!line_dir.empty()) {
        State last = integ->getState();
        m.system.realize(last, Stage::Position);
        check_point_force_lines(m, last, line_dir);
      }
      throw models::NumericalError(
          fmt::format("full model failed at t = {:.6g} s (last step {:.3g} s): {}", integ->getTime(),
                      integ->getPreviousStepSizeTaken(), describe_simbody_exception(e)));
    }
    if (passage) continue;
    record(m, integ->getState(), ts);
    check_finite_row(ts);
    if (opt.branch_guard) check_branch(model, guard, integ->getState(), ts.t[ts.t.size() - 2]);
    motion_scale_J = std::max(
        {motion_scale_J, m.system.calcKineticEnergy(integ->getState()), std::abs(ts.work.back())});
    ++i;
  }
  ts.stats.steps_taken = steps_before_restarts + integ->getNumStepsTaken() + passage_steps;
  ts.stats.steps_attempted = attempts_before_restarts + integ->getNumStepsAttempted() + passage_steps;
  ts.stats.singular_passages = passages;
  ts.stats.events = events_before_restarts + m.events(integ->getState());
  ts.stats.smallest_step_s = std::isfinite(smallest) ? smallest : 0.0;
  ts.stats.wall_time_s = wall();

  // The run checks itself: E(t) − E(0) = W(t) must hold to a fraction of the energy.
  const auto eb = models::energy_balance(ts);
  const double scale_J = std::max(eb.energy_scale_J, motion_scale_J);
  if (!(eb.max_residual_J <= opt.energy_tolerance * scale_J + kEnergyFloor_J))
    throw models::NumericalError(fmt::format(
        "full model's energy balance does not close: max|E − E0 − W| = {:.3g} J at t = {:.6g} s is {:.3g} % of the "
        "energy scale {:.3g} J (largest |E|, kinetic energy or |W|; limit {:g} %): the integration lost or invented "
        "energy ('{}' at tolerance {:g}; try a tighter tolerance or cpodes)",
        eb.max_residual_J, eb.worst_time_s, 100 * eb.max_residual_J / std::max(scale_J, kEnergyFloor_J), scale_J,
        100 * opt.energy_tolerance, opt.integrator, opt.tolerance));
  return ts;
}

}  // namespace rdyn::engine
