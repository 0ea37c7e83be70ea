#include "reduced/simulate_reduced.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

namespace rdyn::reduced {

namespace {

struct OdeContext {
  const ReducedModel* m;
  ReducedWorkspace* ws;
};

// y = (q, q̇, W): W is the work of the non-conservative loads.
int ode_rhs(double, const double y[], double dydt[], void* params) {
  auto* c = static_cast<OdeContext*>(params);
  double qdd, p;
  calc_acceleration(*c->m, *c->ws, y[0], y[1], qdd, p);
  dydt[0] = y[1];
  dydt[1] = qdd;
  dydt[2] = p;
  return std::isfinite(qdd) ? GSL_SUCCESS : GSL_EBADFUNC;
}

const gsl_odeiv2_step_type* step_type(const std::string& name) {
  if (name == "rk8pd") return gsl_odeiv2_step_rk8pd;
  if (name == "rkf45") return gsl_odeiv2_step_rkf45;
  if (name == "rkck") return gsl_odeiv2_step_rkck;
  return nullptr;
}

template <typename T, void (*F)(T*)>
struct Deleter {
  void operator()(T* p) const { F(p); }
};

}  // namespace

struct AdaptiveIntegrator::Impl {
  const ReducedModel& m;
  ReducedWorkspace ws;
  OdeContext ctx;
  gsl_odeiv2_system sys;
  std::unique_ptr<gsl_odeiv2_step, Deleter<gsl_odeiv2_step, gsl_odeiv2_step_free>> step, probe;
  std::unique_ptr<gsl_odeiv2_control, Deleter<gsl_odeiv2_control, gsl_odeiv2_control_free>> control;
  std::unique_ptr<gsl_odeiv2_evolve, Deleter<gsl_odeiv2_evolve, gsl_odeiv2_evolve_free>> evolve;
  std::vector<double> s_before;
  double y[3] = {0, 0, 0};
  double h = 1e-3;
  long steps = 0, events = 0;
  double smallest = INFINITY;

  Impl(const ReducedModel& model, double tol, const std::string& method) : m(model), ws(model), ctx{&m, &ws} {
    const gsl_odeiv2_step_type* type = step_type(method);
    if (!type) throw TableError("unknown reduced integrator '" + method + "' (rk8pd, rkf45, rkck, rk4-fixed)");
    if (!(tol > 0)) throw TableError("reduced integrator tolerance must be positive");
    gsl_set_error_handler_off();
    sys = {ode_rhs, nullptr, 3, &ctx};
    step.reset(gsl_odeiv2_step_alloc(type, 3));
    probe.reset(gsl_odeiv2_step_alloc(type, 3));
    control.reset(gsl_odeiv2_control_standard_new(tol, tol, 1.0, 1.0));
    evolve.reset(gsl_odeiv2_evolve_alloc(3));
    s_before.resize(m.gates.size());
  }

  // One single step of size dt from (t0, y0) with the current gates.
  void probe_step(double t0, const double y0[3], double dt, double out[3]) {
    double err[3];
    for (int k = 0; k < 3; ++k) out[k] = y0[k];
    gsl_odeiv2_step_reset(probe.get());
    gsl_odeiv2_step_apply(probe.get(), t0, dt, out, err, nullptr, nullptr, &sys);
  }
};

AdaptiveIntegrator::AdaptiveIntegrator(const ReducedModel& m, double tolerance, const std::string& method)
    : impl_(std::make_unique<Impl>(m, tolerance, method)) {}
AdaptiveIntegrator::~AdaptiveIntegrator() = default;
const ReducedWorkspace& AdaptiveIntegrator::state() const { return impl_->ws; }
long AdaptiveIntegrator::steps() const { return impl_->steps; }
long AdaptiveIntegrator::rejected() const { return static_cast<long>(impl_->evolve->failed_steps); }
long AdaptiveIntegrator::events() const { return impl_->events; }
double AdaptiveIntegrator::smallest_step() const { return std::isfinite(impl_->smallest) ? impl_->smallest : 0.0; }

void AdaptiveIntegrator::reset(double t, double q, double qdot, double work) {
  auto& d = *impl_;
  d.ws.t = t, d.ws.q = q, d.ws.qdot = qdot, d.ws.work = work;
  init_gates(d.m, d.ws);
  d.y[0] = q, d.y[1] = qdot, d.y[2] = work;
  gsl_odeiv2_evolve_reset(d.evolve.get());
}

bool AdaptiveIntegrator::advance(double t_end, double q_stop) {
  auto& d = *impl_;
  const auto& m = d.m;
  const size_t ng = m.gates.size();
  const bool stop_at_q = std::isfinite(q_stop);
  double t = d.ws.t;
  while (t < t_end) {
    const double t_prev = t, y_prev[3] = {d.y[0], d.y[1], d.y[2]};
    for (size_t g = 0; g < ng; ++g) d.s_before[g] = calc_switching(m, static_cast<int>(g), d.y[0], d.y[1]);
    const double stop_before = stop_at_q ? y_prev[0] - q_stop : 0.0;
    const int st = gsl_odeiv2_evolve_apply(d.evolve.get(), d.control.get(), d.step.get(), &d.sys, &t, t_end, &d.h, d.y);
    if (st != GSL_SUCCESS)
      throw TableError(fmt::format("reduced integration failed at t = {:.6g} s: {}", t, gsl_strerror(st)));
    ++d.steps;
    // Anything that happened in this step: a gate's switching function or q − q_stop
    // changing sign. Locate the earliest by bisection on single steps.
    auto happened = [&](const double yy[3], int& which) {
      bool any = false;
      for (size_t g = 0; g < ng; ++g) {
        const double s = calc_switching(m, static_cast<int>(g), yy[0], yy[1]);
        if (d.s_before[g] != 0.0 && (d.s_before[g] > 0) != (s > 0)) any = true, which = static_cast<int>(g);
      }
      if (stop_at_q && stop_before != 0.0 && (stop_before > 0) != (yy[0] - q_stop > 0)) any = true, which = -2;
      return any;
    };
    int which = -1;
    if (happened(d.y, which)) {
      double lo = 0.0, hi = t - t_prev;
      for (int it = 0; it < 200 && hi - lo > 1e-13 * std::max(1.0, t); ++it) {
        const double mid = 0.5 * (lo + hi);
        double yt[3];
        d.probe_step(t_prev, y_prev, mid, yt);
        int w = -1;
        if (happened(yt, w)) hi = mid, which = w;
        else lo = mid;
      }
      d.probe_step(t_prev, y_prev, hi, d.y);
      t = t_prev + hi;
      gsl_odeiv2_evolve_reset(d.evolve.get());
      if (which >= 0) {
        d.ws.gate_on[which] = !d.ws.gate_on[which];
        ++d.events;
      }
    }
    if (t - t_prev > 0 && t < t_end && which == -1) d.smallest = std::min(d.smallest, t - t_prev);
    d.ws.q = d.y[0], d.ws.qdot = d.y[1], d.ws.work = d.y[2], d.ws.t = t;
    if (!std::isfinite(d.ws.q) || !std::isfinite(d.ws.qdot))
      throw TableError(fmt::format("reduced model produced a non-finite state at t = {:.6g} s", t));
    if (!m.table.in_range(d.ws.q))
      throw TableError(fmt::format("reduced model left the validity domain of its table at t = {:.6g} s (q = {:.6g})",
                                   t, d.ws.q));
    if (which == -2) return true;
  }
  return false;
}

namespace {

void record(const ReducedModel& m, ReducedWorkspace& ws, models::TimeSeries& ts, std::vector<double>& f) {
  double qdd, p;
  calc_acceleration(m, ws, ws.q, ws.qdot, qdd, p);
  ts.t.push_back(ws.t);
  ts.q.push_back(ws.q);
  ts.qdot.push_back(ws.qdot);
  ts.qddot.push_back(qdd);
  ts.energy.push_back(calc_energy(m, ws.q, ws.qdot));
  ts.work.push_back(ws.work);
  std::uint32_t mask = 0;
  for (size_t g = 0; g < ws.gate_on.size() && g < 32; ++g)
    if (ws.gate_on[g]) mask |= 1u << g;
  ts.gates.push_back(mask);
  calc_constraint_forces(m, ws, ws.q, ws.qdot, qdd, f.data());
  for (size_t k = 0; k < f.size(); ++k) ts.forces[k].push_back(f[k]);
}

}  // namespace

models::TimeSeries simulate_reduced(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (!(opt.duration_s > 0) || !(opt.output_interval_s > 0))
    throw TableError("duration and output interval must be positive");
  models::TimeSeries ts;
  ts.force_names = m.force_names;
  ts.forces.resize(m.force_names.size());
  std::vector<double> f(m.force_names.size());
  const long n = std::lround(std::floor(opt.duration_s / opt.output_interval_s + 1e-9));

  if (opt.integrator == "rk4-fixed") {
    if (!(opt.fixed_step_s > 0)) throw TableError("fixed step must be positive");
    ReducedWorkspace ws(m);
    ws.q = q0, ws.qdot = qdot0;
    init_gates(m, ws);
    record(m, ws, ts, f);
    for (long i = 1; i <= n; ++i) {
      const double t_out = std::min(opt.duration_s, i * opt.output_interval_s);
      while (ws.t < t_out - 1e-12) {
        step_fixed_rk4(m, ws, std::min(opt.fixed_step_s, t_out - ws.t));
        ++ts.stats.steps_taken;
        if (!std::isfinite(ws.q) || !std::isfinite(ws.qdot))
          throw TableError(fmt::format("reduced model produced a non-finite state at t = {:.6g} s", ws.t));
      }
      ws.t = t_out;
      record(m, ws, ts, f);
    }
    ts.stats.steps_attempted = ts.stats.steps_taken;
    ts.stats.smallest_step_s = opt.fixed_step_s;
  } else {
    AdaptiveIntegrator integ(m, opt.tolerance, opt.integrator);
    integ.reset(0.0, q0, qdot0);
    ReducedWorkspace ws = integ.state();
    record(m, ws, ts, f);
    for (long i = 1; i <= n; ++i) {
      integ.advance(std::min(opt.duration_s, i * opt.output_interval_s));
      ws = integ.state();
      record(m, ws, ts, f);
    }
    ts.stats.steps_taken = integ.steps();
    ts.stats.steps_attempted = integ.steps() + integ.rejected();
    ts.stats.events = integ.events();
    ts.stats.smallest_step_s = integ.smallest_step();
  }
  ts.stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ts;
}

}  // namespace rdyn::reduced
