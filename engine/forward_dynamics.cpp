#include "engine/forward_dynamics.hpp"

#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "engine/full_model_impl.hpp"
#include "engine/kinetostatic.hpp"

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
  for (size_t i = 0; i < sc.joint_torques.size(); ++i) {
    const auto& gate = sc.joint_torques[i].active_when;
    if (!gate) continue;
    const int j = sc.joint_index(gate->joint);
    m.system.realize(s, Stage::Velocity);
    const double rate = m.joint_u(s, j);
    if (std::abs(rate) > 1e-12) {
      m.set_gate(s, static_cast<int>(i), gate->sign * rate > 0.0);
      continue;
    }
    m.set_gate(s, static_cast<int>(i), true);
    m.system.realize(s, Stage::Acceleration);
    const auto& mb = m.joint_mobod[j];
    const double acc = m.joint_fold[j] ? 0.0 : mb.getOneUDot(s, MobilizerUIndex(0));
    m.set_gate(s, static_cast<int>(i), gate->sign * acc > 0.0);
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
  for (size_t i = 0, g = 0; i < m.scene.joint_torques.size(); ++i)
    if (m.scene.joint_torques[i].active_when) {
      if (m.gate(s, static_cast<int>(i)) && g < 32) mask |= 1u << g;
      ++g;
    }
  ts.gates.push_back(mask);
  const auto f = m.constraint_forces(s);
  for (size_t k = 0; k < f.size(); ++k) ts.forces[k].push_back(f[k]);
  ts.stats.max_constraint_error = std::max(ts.stats.max_constraint_error, m.worst_loop_gap(s).first);
}

}  // namespace

TimeSeries simulate_full(const FullModel& model, const ForwardOptions& opt) {
  const auto& m = model.impl();
  if (!(opt.duration_s > 0) || !(opt.output_interval_s > 0))
    throw EngineError("duration and output interval must be positive");
  const auto start = std::chrono::steady_clock::now();

  // Consistent initial state: a kinetostatic projection at (q0, q̇0), then the independent
  // coordinate is released.
  FullWorkspace ws(model);
  calc_kinetostatic(model, ws, m.scene.initial.q, m.scene.initial.qdot, 0.0, Loads::Off);
  State s = ws.impl().state;
  m.independent_motion.disable(s);
  m.system.realizeModel(s);
  s.setTime(0.0);
  m.set_load_mode(s, kLoadsEvents);
  m.forces.updZ(s)[m.work_index] = 0.0;
  initialize_gates(m, s);

  auto integ = make_integrator(m, opt.integrator);
  integ->setAccuracy(opt.tolerance);
  integ->setConstraintTolerance(std::min(1e-10, opt.tolerance));
  integ->setReturnEveryInternalStep(true);  // to track the smallest step
  // Step freely and interpolate (then project) the states at output times, rather than
  // shortening steps to land on them: the full model's cheapest honest setting.
  integ->setAllowInterpolation(true);
  integ->setProjectInterpolatedStates(true);
  TimeStepper stepper(m.system, *integ);
  stepper.setReportAllSignificantStates(false);
  try {
    stepper.initialize(s);
  } catch (const std::exception& e) {
    throw EngineError(std::string("cannot start the full model: ") + e.what());
  }

  m.events_handled = 0;
  TimeSeries ts;
  for (const auto& c : m.scene.outputs.constraint_forces) ts.force_names.push_back(c.name);
  ts.forces.resize(ts.force_names.size());
  const long n = std::lround(std::floor(opt.duration_s / opt.output_interval_s + 1e-9));
  record(m, integ->getState(), ts);
  double smallest = INFINITY;
  for (long i = 1; i <= n; ++i) {
    const double t = std::min(opt.duration_s, i * opt.output_interval_s);
    try {
      while (integ->getTime() < t - 1e-14) {
        stepper.stepTo(t);
        const double h = integ->getPreviousStepSizeTaken();
        if (h > 0) smallest = std::min(smallest, h);
      }
    } catch (const std::exception& e) {
      throw EngineError(fmt::format("full model failed at t = {:.6g} s: {}", integ->getTime(), e.what()));
    }
    record(m, integ->getState(), ts);
    if (!std::isfinite(ts.qdot.back()))
      throw EngineError(fmt::format("full model produced a non-finite speed at t = {:.6g} s", t));
  }
  ts.stats.steps_taken = integ->getNumStepsTaken();
  ts.stats.steps_attempted = integ->getNumStepsAttempted();
  ts.stats.events = m.events_handled;
  ts.stats.smallest_step_s = std::isfinite(smallest) ? smallest : 0.0;
  ts.stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ts;
}

}  // namespace rdyn::engine
