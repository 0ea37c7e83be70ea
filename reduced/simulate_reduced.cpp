#include "reduced/simulate_reduced.hpp"

#include <chrono>
#include <cmath>
#include <memory>

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

void record(const ReducedModel& m, ReducedWorkspace& ws, models::TimeSeries& ts, std::vector<double>& f) {
  double qdd, p;
  calc_acceleration(m, ws, ws.q, ws.qdot, qdd, p);
  ts.t.push_back(ws.t);
  ts.q.push_back(ws.q);
  ts.qdot.push_back(ws.qdot);
  ts.qddot.push_back(qdd);
  ts.energy.push_back(calc_energy(m, ws.q, ws.qdot));
  ts.work.push_back(ws.work);
  calc_constraint_forces(m, ws, ws.q, ws.qdot, qdd, f.data());
  for (size_t k = 0; k < f.size(); ++k) ts.forces[k].push_back(f[k]);
}

const gsl_odeiv2_step_type* step_type(const std::string& name) {
  if (name == "rk8pd") return gsl_odeiv2_step_rk8pd;
  if (name == "rkf45") return gsl_odeiv2_step_rkf45;
  if (name == "rkck") return gsl_odeiv2_step_rkck;
  return nullptr;
}

}  // namespace

models::TimeSeries simulate_reduced(const ReducedModel& m, double q0, double qdot0, const ReducedOptions& opt) {
  const auto start = std::chrono::steady_clock::now();
  if (!(opt.duration_s > 0) || !(opt.output_interval_s > 0)) throw TableError("duration and output interval must be positive");
  ReducedWorkspace ws(m);
  ws.q = q0;
  ws.qdot = qdot0;
  init_gates(m, ws);

  models::TimeSeries ts;
  ts.force_names = m.force_names;
  ts.forces.resize(m.force_names.size());
  std::vector<double> f(m.force_names.size());
  const long n = std::lround(std::floor(opt.duration_s / opt.output_interval_s + 1e-9));
  auto check = [&] {
    if (!std::isfinite(ws.q) || !std::isfinite(ws.qdot))
      throw TableError(fmt::format("reduced model produced a non-finite state at t = {:.6g} s", ws.t));
    if (!m.table.in_range(ws.q))
      throw TableError(fmt::format("reduced model left the validity domain of its table at t = {:.6g} s "
                                   "(q = {:.6g})", ws.t, ws.q));
  };
  record(m, ws, ts, f);

  if (opt.integrator == "rk4-fixed") {
    if (!(opt.fixed_step_s > 0)) throw TableError("fixed step must be positive");
    for (long i = 1; i <= n; ++i) {
      const double t_out = std::min(opt.duration_s, i * opt.output_interval_s);
      while (ws.t < t_out - 1e-12) {
        step_fixed_rk4(m, ws, std::min(opt.fixed_step_s, t_out - ws.t));
        ++ts.stats.steps_taken;
        check();
      }
      ws.t = t_out;
      record(m, ws, ts, f);
    }
    ts.stats.steps_attempted = ts.stats.steps_taken;
    ts.stats.smallest_step_s = opt.fixed_step_s;
    ts.stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return ts;
  }

  const gsl_odeiv2_step_type* type = step_type(opt.integrator);
  if (!type) throw TableError("unknown reduced integrator '" + opt.integrator + "' (rk8pd, rkf45, rkck, rk4-fixed)");
  gsl_set_error_handler_off();
  OdeContext ctx{&m, &ws};
  gsl_odeiv2_system sys{ode_rhs, nullptr, 3, &ctx};
  std::unique_ptr<gsl_odeiv2_step, decltype(&gsl_odeiv2_step_free)> step(gsl_odeiv2_step_alloc(type, 3),
                                                                        gsl_odeiv2_step_free);
  std::unique_ptr<gsl_odeiv2_step, decltype(&gsl_odeiv2_step_free)> probe(gsl_odeiv2_step_alloc(type, 3),
                                                                         gsl_odeiv2_step_free);
  std::unique_ptr<gsl_odeiv2_control, decltype(&gsl_odeiv2_control_free)> control(
      gsl_odeiv2_control_standard_new(opt.tolerance, opt.tolerance, 1.0, 1.0), gsl_odeiv2_control_free);
  std::unique_ptr<gsl_odeiv2_evolve, decltype(&gsl_odeiv2_evolve_free)> evolve(gsl_odeiv2_evolve_alloc(3),
                                                                               gsl_odeiv2_evolve_free);
  const size_t ng = m.gates.size();
  std::vector<double> s_before(ng), s_after(ng);
  double y[3] = {ws.q, ws.qdot, ws.work};
  double t = 0.0, h = std::min(1e-3, opt.output_interval_s);
  double smallest = INFINITY;

  for (long i = 1; i <= n; ++i) {
    const double t_out = std::min(opt.duration_s, i * opt.output_interval_s);
    while (t < t_out) {
      const double t_prev = t, y_prev[3] = {y[0], y[1], y[2]};
      for (size_t g = 0; g < ng; ++g) s_before[g] = calc_switching(m, static_cast<int>(g), y[0], y[1]);
      const int st = gsl_odeiv2_evolve_apply(evolve.get(), control.get(), step.get(), &sys, &t, t_out, &h, y);
      if (st != GSL_SUCCESS) throw TableError(fmt::format("reduced integration failed at t = {:.6g} s: {}", t, gsl_strerror(st)));
      ++ts.stats.steps_taken;
      // Earliest switching-function sign change in this step.
      int which = -1;
      for (size_t g = 0; g < ng; ++g) {
        s_after[g] = calc_switching(m, static_cast<int>(g), y[0], y[1]);
        if ((s_before[g] > 0) != (s_after[g] > 0) && s_before[g] != 0.0) which = static_cast<int>(g);
      }
      if (which >= 0) {
        // Locate the crossing: bisection on the step size, each trial a single step of the
        // same method from the start of the step (gates frozen as they were).
        double lo = 0.0, hi = t - t_prev;
        int first = which;
        for (int it = 0; it < 200 && hi - lo > 1e-13 * std::max(1.0, t); ++it) {
          const double mid = 0.5 * (lo + hi);
          double yt[3] = {y_prev[0], y_prev[1], y_prev[2]}, err[3];
          gsl_odeiv2_step_reset(probe.get());
          gsl_odeiv2_step_apply(probe.get(), t_prev, mid, yt, err, nullptr, nullptr, &sys);
          bool crossed = false;
          for (size_t g = 0; g < ng; ++g) {
            const double s = calc_switching(m, static_cast<int>(g), yt[0], yt[1]);
            if ((s_before[g] > 0) != (s > 0) && s_before[g] != 0.0) crossed = true, first = static_cast<int>(g);
          }
          (crossed ? hi : lo) = mid;
        }
        double yt[3] = {y_prev[0], y_prev[1], y_prev[2]}, err[3];
        gsl_odeiv2_step_reset(probe.get());
        gsl_odeiv2_step_apply(probe.get(), t_prev, hi, yt, err, nullptr, nullptr, &sys);
        for (int k = 0; k < 3; ++k) y[k] = yt[k];
        t = t_prev + hi;
        ws.gate_on[first] = !ws.gate_on[first];
        ++ts.stats.events;
        gsl_odeiv2_evolve_reset(evolve.get());
      }
      if (t - t_prev > 0 && t < t_out) smallest = std::min(smallest, t - t_prev);
      ws.q = y[0], ws.qdot = y[1], ws.work = y[2], ws.t = t;
      check();
    }
    record(m, ws, ts, f);
  }
  ts.stats.steps_attempted = static_cast<long>(evolve->count);
  ts.stats.smallest_step_s = std::isfinite(smallest) ? smallest : 0.0;
  ts.stats.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return ts;
}

}  // namespace rdyn::reduced
