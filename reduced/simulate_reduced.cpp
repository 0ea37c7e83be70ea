#include "reduced/simulate_reduced.hpp"

#include <array>
#include <chrono>
#include <optional>
#include <cmath>
#include <algorithm>
#include <cstdint>

#include <fmt/format.h>

namespace rdyn::reduced {

namespace {

// Appends one output sample at (t, q, q̇, W) with the workspace's gates.
void record(const ReducedModel& m, ReducedWorkspace& ws, double t, double q, double qdot, double work,
            models::TimeSeries& ts, std::vector<double>& f) {
  if (!m.force_poles.empty()) check_force_poles(m, q, t);
  double qdd, p;
  const double energy = calc_sample(m, ws, q, qdot, qdd, p, f.data());
  // No NaN in an output: a sample that is not finite fails the run, naming what and when (the
  // names are built only then: a string per force per row was a third of the row's cost).
  bool all_finite = std::isfinite(q) && std::isfinite(qdot) && std::isfinite(qdd) && std::isfinite(energy) &&
                    std::isfinite(work);
  for (double fk : f) all_finite = all_finite && std::isfinite(fk);
  if (!all_finite) {
    auto finite = [&](double v, const std::string& what) {
      if (!std::isfinite(v))
        throw models::NumericalError(
            fmt::format("reduced model output {} is not finite ({}) at t = {:.6g} s", what, v, t));
    };
    finite(q, "q");
    finite(qdot, "q̇");
    finite(qdd, "q̈");
    finite(energy, "energy");
    finite(work, "work");
    for (size_t k = 0; k < f.size(); ++k) finite(f[k], "constraint force '" + m.force_names[k] + "'");
  }
  ts.t.push_back(t);
  ts.q.push_back(q);
  ts.qdot.push_back(qdot);
  ts.qddot.push_back(qdd);
  ts.energy.push_back(energy);
  ts.work.push_back(work);
  std::uint32_t mask = 0;
  for (size_t g = 0; g < ws.gate_on.size() && g < 32; ++g)
    if (ws.gate_on[g]) mask |= 1u << g;
  ts.gates.push_back(mask);
  for (size_t k = 0; k < f.size(); ++k) ts.forces[k].push_back(f[k]);
}

}  // namespace

void check_reduced_options(const ReducedOptions& opt) {
  if (!(std::isfinite(opt.duration_s) && opt.duration_s > 0))
    throw TableError(fmt::format("reduced simulation duration {:g} s must be finite and positive", opt.duration_s));
  if (!(std::isfinite(opt.output_interval_s) && opt.output_interval_s > 0))
    throw TableError(
        fmt::format("reduced simulation output interval {:g} s must be finite and positive", opt.output_interval_s));
  const double rows = static_cast<double>(models::calc_output_rows(opt.duration_s, opt.output_interval_s)) + 1;
  if (!(rows <= static_cast<double>(kMaxOutputRows)))
    throw TableError(fmt::format(
        "reduced simulation: duration {:g} s / output interval {:g} s gives {:.3g} output rows, more than the limit of {}",
        opt.duration_s, opt.output_interval_s, rows, kMaxOutputRows));
  if (!(opt.max_steps > 0) || !(opt.max_wall_s > 0))
    throw TableError("reduced simulation step and wall-time budgets must be positive");
  if (opt.integrator == "rk4-fixed") {
    if (!(opt.fixed_step_s >= kMinFixedStep_s && opt.fixed_step_s <= kMaxFixedStep_s))
      throw TableError(fmt::format("reduced fixed step {:g} s is out of range [{:g}, {:g}] s", opt.fixed_step_s,
                                   kMinFixedStep_s, kMaxFixedStep_s));
    const double steps = std::ceil(opt.duration_s / opt.fixed_step_s);
    if (!(steps <= static_cast<double>(opt.max_steps)))
      throw TableError(fmt::format("reduced simulation: duration {:g} s at fixed step {:g} s needs {:.3g} steps, more "
                                   "than the budget of {}",
                                   opt.duration_s, opt.fixed_step_s, steps, opt.max_steps));
  } else {
    if (!is_adaptive_method(opt.integrator))
      throw TableError("unknown reduced integrator '" + opt.integrator + "' (rk8pd, rkf45, rkck, rk4-fixed)");
    if (!(opt.tolerance >= kMinTolerance && opt.tolerance <= kMaxTolerance))
      throw TableError(fmt::format("reduced integrator tolerance {:g} is out of range [{:g}, {:g}]", opt.tolerance,
                                   kMinTolerance, kMaxTolerance));
  }
}

namespace {

void check_simulation_start(const ReducedModel& m, double q0, double qdot0) {
  if (!std::isfinite(q0) || !std::isfinite(qdot0))
    throw TableError(fmt::format("reduced simulation start (q, q̇) = ({}, {}) is not finite", q0, qdot0));
  if (!m.table.in_range(q0))
    throw TableError(fmt::format("reduced simulation start {} lies outside its table's range, from {} to {}",
                                 describe_q(m.revolute, q0), describe_q(m.revolute, m.table.q0),
                                 describe_q(m.revolute, m.table.q0 + m.table.intervals * m.table.step)));
}

// The output rows of a run: n + 1 of them, the last at t = duration.
struct OutputGrid {
  long n;
  const ReducedOptions& opt;
  double t(long i) const { return models::calc_output_time(i, n, opt.duration_s, opt.output_interval_s); }
};

void reserve_series(const ReducedModel& m, long n, models::TimeSeries& ts) {
  ts.force_names = m.force_names;
  ts.forces.resize(m.force_names.size());
  for (auto* v : {&ts.t, &ts.q, &ts.qdot, &ts.qddot, &ts.energy, &ts.work}) v->reserve(n + 1);
  for (auto& v : ts.forces) v.reserve(n + 1);
  ts.gates.reserve(n + 1);
}

// The divergence guard's message (both integrators): the reduced equation's own energy balance
// E − E0 = W must hold to interpolation accuracy; a gross failure means the table is too coarse.
[[noreturn]] void throw_divergence(const DivergenceGuard& guard, double t, double E, double work, const char* advice) {
  throw models::NumericalError(fmt::format(
      "reduced model diverges at t = {:.6g} s: its energy balance is off by {:.3g} J (energy {:.3g} J, "
      "initially {:.3g} J, work of the loads {:.3g} J) — {}",
      t, E - guard.energy0 - work, E, guard.energy0, work, advice));
}

// Fixed RK4 steps regardless of the outputs; outputs by quintic Hermite inside each step (linear
// across a gate switch), or, with step_outputs, one RK4 step of the row's length from the step's
// start.
class FixedStepRun {
 public:
  FixedStepRun(const ReducedModel& m, const ReducedOptions& opt, OutputGrid grid, models::TimeSeries& ts,
               std::chrono::steady_clock::time_point start)
      : m_(m), opt_(opt), grid_(grid), ts_(ts), start_(start), ws_(m), before_(0), f_(m.force_names.size()) {
    // step_outputs: the step's start, and a row's sub-step (made only then: a workspace is a
    // dozen allocations, ~10 % of a 5 s run at 50 ms steps).
    if (opt.step_outputs) at_start_.emplace(m), sub_.emplace(m);
  }

  void run(double q0, double qdot0) {
    ws_.q = q0, ws_.qdot = qdot0;
    init_gates(m_, ws_);
    before_.resize(ws_.gate_on.size());
    record(m_, ws_, 0.0, q0, qdot0, 0.0, ts_, f_);
    DivergenceGuard guard = start_divergence_guard(ts_.energy.front(), calc_potential_min(m_), 0.0);
    long i = 1;
    AdaptiveIntegrator::Point a = point();
    while (i <= grid_.n) {
      std::copy(ws_.gate_on.begin(), ws_.gate_on.end(), before_.begin());
      if (opt_.step_outputs) *at_start_ = ws_;
      check_budgets();
      // a: the step's start point, with the gates ws holds now: its q̈ and power are RK4's k1.
      const double k1[2] = {a.qddot, a.power};
      const double t_switch = step_fixed_rk4(m_, ws_, std::min(opt_.fixed_step_s, opt_.duration_s - ws_.t), k1);
      ++ts_.stats.steps_taken;
      if (!std::isnan(t_switch)) ++ts_.stats.events;
      check_step_end(a);
      const AdaptiveIntegrator::Point b = point();
      if (divergence_guard_fires(guard, e_point_, b.work))
        throw_divergence(guard, b.t, e_point_, b.work, "the table or the fixed step is too coarse for this run");
      i = record_rows(i, a, b, t_switch, k1);
      a = b;
      if (ws_.t >= opt_.duration_s - 1e-12) break;
    }
    ts_.stats.steps_attempted = ts_.stats.steps_taken;
    ts_.stats.smallest_step_s = opt_.fixed_step_s;
  }

 private:
  // The workspace's state as a point, with its q̈ and power; its energy in e_point_ (one lookup).
  AdaptiveIntegrator::Point point() {
    AdaptiveIntegrator::Point p{ws_.t, ws_.q, ws_.qdot, 0, ws_.work, 0};
    e_point_ = calc_acceleration_energy(m_, ws_, p.q, p.qdot, p.qddot, p.power);
    return p;
  }

  // Budgets (the step count was checked against the duration; this also catches a time that
  // stops advancing in floating point). The clock is read every 64 steps.
  void check_budgets() const {
    if (ts_.stats.steps_taken >= opt_.max_steps)
      throw models::NumericalError(fmt::format(
          "reduced integration stopped at t = {:.6g} s: it used its budget of {} fixed steps", ws_.t, opt_.max_steps));
    if (ts_.stats.steps_taken % 64 == 0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count() > opt_.max_wall_s)
      throw models::NumericalError(fmt::format(
          "reduced integration stopped at t = {:.6g} s: it used its wall-time budget of {:g} s after {} steps", ws_.t,
          opt_.max_wall_s, ts_.stats.steps_taken));
  }

  void check_step_end(const AdaptiveIntegrator::Point& a) const {
    if (!std::isfinite(ws_.q) || !std::isfinite(ws_.qdot) || !std::isfinite(ws_.work))
      throw models::NumericalError(fmt::format("reduced model produced a non-finite state at t = {:.6g} s", ws_.t));
    if (!m_.table.in_range(ws_.q)) {  // edge of a range table, crossed within this step (linear estimate)
      const double edge = domain_edge(m_, ws_.q);
      throw_left_domain(m_, edge, a.t + (ws_.t - a.t) * (edge - a.q) / (ws_.q - a.q));
    }
  }

  // The rows from i that fall in the step [a, b]; returns the next row. A switch inside the step
  // breaks the smoothness Hermite assumes: linear interpolation there, with the gates that held
  // at each row's time (the fixed-step path is the real-time one; accuracy is secondary).
  long record_rows(long i, const AdaptiveIntegrator::Point& a, const AdaptiveIntegrator::Point& b, double t_switch,
                   const double k1[2]) {
    for (; i <= grid_.n && grid_.t(i) <= b.t + 1e-12; ++i) {
      const double t = grid_.t(i), s = (t - a.t) / (b.t - a.t);
      if (opt_.step_outputs && t < b.t) {
        // One RK4 step of the row's length from the step's start (switches located as in the
        // step itself), with the gates that hold at the row's time.
        *sub_ = *at_start_;
        step_fixed_rk4(m_, *sub_, t - a.t, k1);
        ws_.gate_on.swap(sub_->gate_on);
        record(m_, ws_, t, sub_->q, sub_->qdot, sub_->work, ts_, f_);
        ws_.gate_on.swap(sub_->gate_on);
        continue;
      }
      double q, v, w;
      if (!std::isnan(t_switch)) q = a.q + s * (b.q - a.q), v = a.qdot + s * (b.qdot - a.qdot), w = a.work + s * (b.work - a.work);
      else calc_hermite(a, b, s, q, v, w);
      if (t < t_switch) ws_.gate_on.swap(before_);
      record(m_, ws_, t, q, v, w, ts_, f_);
      if (t < t_switch) ws_.gate_on.swap(before_);
    }
    return i;
  }

  const ReducedModel& m_;
  const ReducedOptions& opt_;
  OutputGrid grid_;
  models::TimeSeries& ts_;
  std::chrono::steady_clock::time_point start_;
  ReducedWorkspace ws_;
  std::vector<char> before_;
  std::optional<ReducedWorkspace> at_start_, sub_;
  std::vector<double> f_;
  double e_point_ = 0.0;  // energy at the last point()
};

// GSL's adaptive steps; outputs by quintic Hermite inside each step, or, with step_outputs, the
// stepper's own dense output.
void run_adaptive(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt, OutputGrid grid,
                  models::TimeSeries& ts) {
  std::vector<double> f(m.force_names.size());
  AdaptiveIntegrator integ(m, opt.tolerance, opt.integrator, IntegratorLimits{opt.max_steps, opt.max_wall_s});
  integ.reset(0.0, q0, qdot0);
  ReducedWorkspace& ws = const_cast<ReducedWorkspace&>(integ.state());
  record(m, ws, 0.0, q0, qdot0, 0.0, ts, f);
  DivergenceGuard guard = start_divergence_guard(ts.energy.front(), calc_potential_min(m), 0.0);
  long i = 1;
  while (i <= grid.n) {
    integ.step(opt.duration_s);
    const auto& a = integ.step_start();
    const auto& b = integ.step_end();
    const double E = calc_energy(m, b.q, b.qdot);
    if (divergence_guard_fires(guard, E, b.work))
      throw_divergence(guard, b.t, E, b.work,
                       "the table is too coarse for this run (refine the grid, or use --energy-consistent)");
    for (; i <= grid.n && grid.t(i) <= b.t + 1e-12 * std::max(1.0, b.t); ++i) {
      double q, v, w;
      if (b.t - a.t <= 0 || grid.t(i) >= b.t) {
        q = b.q, v = b.qdot, w = b.work;
      } else if (opt.step_outputs) {
        double y[3];
        integ.calc_within_step(grid.t(i), y);
        q = y[0], v = y[1], w = y[2];
      } else {
        calc_hermite(a, b, (grid.t(i) - a.t) / (b.t - a.t), q, v, w);
      }
      record(m, ws, grid.t(i), q, v, w, ts, f);
    }
  }
  ts.stats.steps_taken = integ.steps();
  ts.stats.steps_attempted = integ.steps() + integ.rejected();
  ts.stats.events = integ.events();
  ts.stats.smallest_step_s = integ.smallest_step();
}

}  // namespace

models::TimeSeries simulate_reduced(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  check_reduced_options(opt);  // before any allocation
  check_simulation_start(m, q0, qdot0);
  const OutputGrid grid{models::calc_output_rows(opt.duration_s, opt.output_interval_s), opt};
  models::TimeSeries ts;
  reserve_series(m, grid.n, ts);
  if (opt.integrator == "rk4-fixed") FixedStepRun(m, opt, grid, ts, start).run(q0, qdot0);
  else run_adaptive(m, q0, qdot0, opt, grid, ts);
  ts.stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ts;
}

void check_energy_balance(const models::TimeSeries& ts, double tolerance, const std::string& how) {
  if (ts.t.empty()) return;
  const auto eb = models::energy_balance(ts);
  double scale_J = eb.energy_scale_J;
  const auto [lo, hi] = std::minmax_element(ts.energy.begin(), ts.energy.end());
  scale_J = std::max(scale_J, *hi - *lo);
  for (double w : ts.work) scale_J = std::max(scale_J, std::abs(w));
  if (eb.max_residual_J <= tolerance * scale_J + 1e-12) return;
  throw EnergyBalanceError(fmt::format(
      "reduced model's energy balance does not close: max|E − E0 − W| = {:.3g} J at t = {:.6g} s is {:.3g} % of the "
      "energy scale {:.3g} J (largest |E|, |W| or range of E; limit {:g} %): the integration lost or invented energy "
      "({}; a fixed step too long, or a table too coarse for the motion — its interpolated m2 is then not "
      "½ dm1/dq of its m1: try a shorter fixed step, an adaptive integrator, or a finer --grid-deg)",
      eb.max_residual_J, eb.worst_time_s, 100 * eb.max_residual_J / std::max(scale_J, 1e-300), scale_J,
      100 * tolerance, how));
}

}  // namespace rdyn::reduced
