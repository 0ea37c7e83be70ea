#include "reduced/simulate_reduced.hpp"

#include <array>
#include <chrono>
#include <optional>
#include <cmath>
#include <algorithm>
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

// Quintic Hermite through (q, q̇, q̈) at both ends of a step of length H, at fraction s;
// cubic Hermite for W through (W, P). q̈ at the sample is recomputed from the model.
void hermite(const AdaptiveIntegrator::Point& a, const AdaptiveIntegrator::Point& b, double s, double& q,
             double& qdot, double& work) {
  const double H = b.t - a.t;
  const double V0 = a.qdot * H, A0 = a.qddot * H * H, V1 = b.qdot * H, A1 = b.qddot * H * H;
  const double d0 = b.q - a.q - V0 - 0.5 * A0, d1 = V1 - V0 - A0, d2 = A1 - A0;
  const double c3 = 10 * d0 - 4 * d1 + 0.5 * d2, c4 = -15 * d0 + 7 * d1 - d2, c5 = 6 * d0 - 3 * d1 + 0.5 * d2;
  q = a.q + s * (V0 + s * (0.5 * A0 + s * (c3 + s * (c4 + s * c5))));
  qdot = (V0 + s * (A0 + s * (3 * c3 + s * (4 * c4 + s * 5 * c5)))) / H;
  const double h00 = 2 * s * s * s - 3 * s * s + 1, h10 = s * s * s - 2 * s * s + s, h01 = -2 * s * s * s + 3 * s * s,
               h11 = s * s * s - s * s;
  work = h00 * a.work + h10 * H * a.power + h01 * b.work + h11 * H * b.power;
}

// What a GSL status means here, in plain words: GSL's own texts ("problem with user-supplied
// function") name its API, not the run (issue #23).
std::string describe_gsl_failure(int status, double h) {
  if (status == GSL_EBADFUNC)
    return "the reduced model's acceleration q̈ is not finite there (m1 reaches 0 or a table value is not finite "
           "near this q: a finer grid, or a start farther from a dead point)";
  if (status == GSL_FAILURE)
    return fmt::format("the error control cannot shrink the step below {:.3g} s and still meet the tolerance (the "
                       "motion is too stiff for it: loosen --reduced-tolerance or use a finer grid)",
                       h);
  return fmt::format("the integrator stopped with GSL status {} ({})", status, gsl_strerror(status));
}

// The edge of a range table's validity domain that q has crossed.
double domain_edge(const ReducedModel& m, double q) {
  return q < m.table.q0 ? m.table.q0 : m.table.q0 + m.table.intervals * m.table.step;
}

// A run that reaches the edge of a range table stops (exit 1), as the full model does at the
// same edge (engine/forward_dynamics.cpp): beyond it the table has no data (a dead point, where
// m1 → ∞, or a declared limit).
[[noreturn]] void throw_left_domain(const ReducedModel& m, double edge, double t) {
  const bool at_min = edge == m.table.q0;
  const std::string& kind = at_min ? m.min_edge : m.max_edge;
  throw models::NumericalError(fmt::format(
      "reduced model left the validity domain at {} ({}) at t = {:.6g} s: the table's range ends there",
      m.revolute ? fmt::format("q = {:.9g}°", edge * 180 / M_PI) : fmt::format("q = {:.9g} m", edge),
      kind.empty() ? "edge of the table" : kind, t));
}

}  // namespace

struct AdaptiveIntegrator::Impl {
  const ReducedModel& m;
  ReducedWorkspace ws;
  OdeContext ctx;
  gsl_odeiv2_system sys;
  std::unique_ptr<gsl_odeiv2_step, Deleter<gsl_odeiv2_step, gsl_odeiv2_step_free>> step, probe;
  std::unique_ptr<gsl_odeiv2_control, Deleter<gsl_odeiv2_control, gsl_odeiv2_control_free>> control;
  std::unique_ptr<gsl_odeiv2_evolve, Deleter<gsl_odeiv2_evolve, gsl_odeiv2_evolve_free>> evolve;
  std::vector<double> s_before, s_after;
  double y[3] = {0, 0, 0};
  double h = 1e-3;
  long steps = 0, events = 0;
  double smallest = INFINITY;
  std::vector<char> pending;  // gates to flip before the next step
  bool flipped = false;   // a gate flipped since `end` was computed
  Point start{}, end{};
  IntegratorLimits limits;
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();

  Impl(const ReducedModel& model, double tol, const std::string& method, IntegratorLimits lim)
      : m(model), ws(model), ctx{&m, &ws}, limits(lim) {
    const gsl_odeiv2_step_type* type = step_type(method);
    if (!type) throw TableError("unknown reduced integrator '" + method + "' (rk8pd, rkf45, rkck, rk4-fixed)");
    if (!(tol >= kMinTolerance && tol <= kMaxTolerance))
      throw TableError(fmt::format("reduced integrator tolerance {:g} is out of range [{:g}, {:g}]", tol, kMinTolerance,
                                   kMaxTolerance));
    if (!(limits.max_steps > 0) || !(limits.max_wall_s > 0))
      throw TableError("reduced integrator step and wall-time budgets must be positive");
    gsl_set_error_handler_off();
    sys = {ode_rhs, nullptr, 3, &ctx};
    step.reset(gsl_odeiv2_step_alloc(type, 3));
    probe.reset(gsl_odeiv2_step_alloc(type, 3));
    control.reset(gsl_odeiv2_control_standard_new(tol, tol, 1.0, 1.0));
    evolve.reset(gsl_odeiv2_evolve_alloc(3));
    s_before.resize(m.gates.size());
    s_after.resize(m.gates.size());
    pending.assign(m.gates.size(), 0);
  }

  // One step of gsl_odeiv2_evolve_apply (GSL 2.7, ode-initval2/evolve.c), statement for
  // statement, except for the derivative at the step's start: GSL evaluates it on every call,
  // here it is the start point's (q̈ and power from calc_acceleration, as ode_rhs computes them),
  // which the previous step's end already holds; and that end point is GSL's dydt_out (rk8pd
  // evaluates it for the error control). The same numbers with two right-hand sides fewer per
  // step (13 instead of 15 for rk8pd). Bounded: a step is halved at most kMaxRetries times.
  int evolve_apply(double* t, double t1, double* h_io, double yy[]) {
    gsl_odeiv2_evolve* e = evolve.get();
    const double t0 = *t;
    double h0 = *h_io;
    const double dt = t1 - t0;
    if ((dt < 0.0 && h0 > 0.0) || (dt > 0.0 && h0 < 0.0)) return GSL_EINVAL;
    for (int k = 0; k < 3; ++k) e->y0[k] = yy[k];
    const bool use_in = step->type->can_use_dydt_in;
    if (use_in) {
      e->dydt_in[0] = start.qdot, e->dydt_in[1] = start.qddot, e->dydt_in[2] = start.power;
      if (!std::isfinite(start.qddot)) return GSL_EBADFUNC;  // as ode_rhs would report it
    }
    constexpr int kMaxRetries = 2200;  // halving a double from 1 to below its ulp takes < 1100
    for (int attempt = 0; attempt < kMaxRetries; ++attempt) {
      bool final_step = false;
      if ((dt >= 0.0 && h0 > dt) || (dt < 0.0 && h0 < dt)) {
        h0 = dt;
        final_step = true;
      }
      const int st = gsl_odeiv2_step_apply(step.get(), t0, h0, yy, e->yerr, use_in ? e->dydt_in : nullptr,
                                           e->dydt_out, &sys);
      if (st == GSL_EFAULT || st == GSL_EBADFUNC) return st;
      if (st != GSL_SUCCESS) {  // the stepper could not take the step: halve it
        const double h_old = h0;
        h0 *= 0.5;
        const volatile double t_curr = *t, t_next = *t + h0;
        if (std::abs(h0) < std::abs(h_old) && t_next != t_curr) {
          for (int k = 0; k < 3; ++k) yy[k] = e->y0[k];
          ++e->failed_steps;
          continue;
        }
        *h_io = h0;
        *t = t0;
        return st;
      }
      ++e->count;
      e->last_step = h0;
      *t = final_step ? t1 : t0 + h0;
      const double h_old = h0;
      if (gsl_odeiv2_control_hadjust(control.get(), step.get(), control_scale(yy).data(), e->yerr, e->dydt_out,
                                     &h0) == GSL_ODEIV_HADJ_DEC) {
        const volatile double t_curr = *t, t_next = *t + h0;
        if (std::abs(h0) < std::abs(h_old) && t_next != t_curr) {  // rejected: retry smaller
          for (int k = 0; k < 3; ++k) yy[k] = e->y0[k];
          ++e->failed_steps;
          continue;
        }
        *h_io = h0;
        return GSL_FAILURE;
      }
      if (!final_step) *h_io = h0;
      return GSL_SUCCESS;
    }
    return GSL_FAILURE;
  }

  // The state as the error control sees it. GSL's standard control allows an error of
  // tol (1 + |y_i| + h |y_i'|) per component: relative to |q| for the angle, which is unwrapped,
  // so the allowed error would grow with every turn (a 40-loop chain at 30 rad was held 30 times
  // looser than in its first turn). An angle's size counts at most one turn; runs that stay
  // within one turn see the same control as before.
  std::array<double, 3> control_scale(const double yy[3]) const {
    std::array<double, 3> s{yy[0], yy[1], yy[2]};
    if (m.revolute) s[0] = std::min(std::abs(s[0]), 2 * M_PI);
    return s;
  }

  // The step's end as point() would compute it, from the derivative the stepper evaluated there.
  Point end_point(double t, const double yy[3]) const {
    const double* f = evolve->dydt_out;
    return Point{t, yy[0], yy[1], f[1], yy[2], f[2]};
  }

  Point point(double t, const double yy[3]) {
    Point p{t, yy[0], yy[1], 0, yy[2], 0};
    calc_acceleration(m, ws, p.q, p.qdot, p.qddot, p.power);
    return p;
  }

  // One single step of size dt from (t0, y0) with the current gates.
  void probe_step(double t0, const double y0[3], double dt, double out[3]) {
    double err[3];
    for (int k = 0; k < 3; ++k) out[k] = y0[k];
    gsl_odeiv2_step_reset(probe.get());
    gsl_odeiv2_step_apply(probe.get(), t0, dt, out, err, nullptr, nullptr, &sys);
  }

  // Illinois (modified regula falsi) on f over [a, b] with fa, fb of opposite signs; returns
  // the end of the final bracket on the side whose sign differs from f0.
  template <typename F>
  double illinois(F&& f, double a, double fa, double b, double fb, double f0, double tol) {
    for (int it = 0; it < 100 && std::abs(b - a) > tol; ++it) {
      double c = b - fb * (b - a) / (fb - fa);
      if (!(c > std::min(a, b) && c < std::max(a, b))) c = 0.5 * (a + b);
      const double fc = f(c);
      if (fc == 0.0) return c;
      if ((fc > 0) != (fb > 0)) {
        a = b;
        fa = fb;
      } else {
        fa *= 0.5;
      }
      b = c;
      fb = fc;
    }
    return (fa > 0) != (f0 > 0) ? a : b;
  }

  // Crossing of g (a function of q, q̇) inside the last step [0, H]: estimated on the step's
  // quintic Hermite interpolant (no model calls), refined by Newton's method along the
  // trajectory with single steps from the start of the step (dg/dt = g_q q̇ + g_q̇ q̈, the
  // partials by central differences of g), then moved just past the crossing so the sign
  // has changed where the step is cut. Typically three single steps per crossing.
  struct Cut {
    double h = 0.0;
    double y[3] = {0, 0, 0};
  };
  template <typename G>
  Cut locate(G&& g, double t0, const double y0[3], double H, double g0, double gH) {
    const double tol = 1e-13 * std::max(1.0, std::abs(t0));
    auto on_hermite = [&](double hh) {
      double q, v, w;
      hermite(start, end, hh / H, q, v, w);
      return g(q, v);
    };
    auto crossed = [&](double gv) { return gv != 0.0 && (gv > 0) != (g0 > 0); };
    Cut c;
    c.h = illinois(on_hermite, 0.0, g0, H, gH, g0, tol);
    // Newton to the crossing (accept a point already past it once the correction is tiny).
    for (int it = 0; it < 8; ++it) {
      probe_step(t0, y0, c.h, c.y);
      const double gv = g(c.y[0], c.y[1]);
      double a, p;
      calc_acceleration(m, ws, c.y[0], c.y[1], a, p);
      const double dq = 1e-7 * std::max(1.0, std::abs(c.y[0])), dv = 1e-7 * std::max(1.0, std::abs(c.y[1]));
      const double gq = (g(c.y[0] + dq, c.y[1]) - g(c.y[0] - dq, c.y[1])) / (2 * dq);
      const double gw = (g(c.y[0], c.y[1] + dv) - g(c.y[0], c.y[1] - dv)) / (2 * dv);
      const double rate = gq * c.y[1] + gw * a;
      const double dh = std::isfinite(rate) && rate != 0.0 ? -gv / rate : 0.0;
      if (std::abs(dh) <= 1e3 * tol) {
        if (crossed(gv)) return c;  // just past the crossing
        break;                      // at (or just before) it: step over below
      }
      c.h = std::min(H, std::max(0.0, c.h + dh));
    }
    // Step just over the crossing.
    const double root = c.h;
    for (double nudge = tol; c.h < H; nudge *= 4) {
      c.h = std::min(H, root + nudge);
      probe_step(t0, y0, c.h, c.y);
      if (crossed(g(c.y[0], c.y[1]))) return c;
    }
    c.h = H;  // the step's end has crossed by construction
    probe_step(t0, y0, H, c.y);
    return c;
  }
};

AdaptiveIntegrator::AdaptiveIntegrator(const ReducedModel& m, double tolerance, const std::string& method,
                                       IntegratorLimits limits)
    : impl_(std::make_unique<Impl>(m, tolerance, method, limits)) {}
AdaptiveIntegrator::~AdaptiveIntegrator() = default;
const ReducedWorkspace& AdaptiveIntegrator::state() const { return impl_->ws; }
long AdaptiveIntegrator::steps() const { return impl_->steps; }
long AdaptiveIntegrator::rejected() const { return static_cast<long>(impl_->evolve->failed_steps); }
long AdaptiveIntegrator::events() const { return impl_->events; }
double AdaptiveIntegrator::smallest_step() const { return std::isfinite(impl_->smallest) ? impl_->smallest : 0.0; }
const AdaptiveIntegrator::Point& AdaptiveIntegrator::step_start() const { return impl_->start; }
void AdaptiveIntegrator::calc_within_step(double t, double y[3]) {
  const Point& a = impl_->start;
  const double y0[3] = {a.q, a.qdot, a.work};
  impl_->probe_step(a.t, y0, t - a.t, y);
}
const AdaptiveIntegrator::Point& AdaptiveIntegrator::step_end() const { return impl_->end; }

void AdaptiveIntegrator::reset(double t, double q, double qdot, double work) {
  auto& d = *impl_;
  d.ws.t = t, d.ws.q = q, d.ws.qdot = qdot, d.ws.work = work;
  init_gates(d.m, d.ws);
  d.y[0] = q, d.y[1] = qdot, d.y[2] = work;
  std::fill(d.pending.begin(), d.pending.end(), 0);
  d.flipped = true;  // recompute the start point and switching values
  d.start = d.end = d.point(t, d.y);
  gsl_odeiv2_evolve_reset(d.evolve.get());
}

bool AdaptiveIntegrator::step(double t_end, double q_stop) {
  auto& d = *impl_;
  const auto& m = d.m;
  // Budgets: every run ends, in steps and in wall time (the clock is read every 64 steps).
  const long attempted = d.steps + static_cast<long>(d.evolve->failed_steps);
  if (attempted >= d.limits.max_steps)
    throw models::NumericalError(fmt::format(
        "reduced integration stopped at t = {:.6g} s: it used its budget of {} steps (the run needs more; "
        "loosen the tolerance or shorten the duration)",
        d.ws.t, d.limits.max_steps));
  if (d.steps % 64 == 0) {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - d.started).count();
    if (wall > d.limits.max_wall_s)
      throw models::NumericalError(fmt::format(
          "reduced integration stopped at t = {:.6g} s: it used its wall-time budget of {:g} s after {} steps",
          d.ws.t, d.limits.max_wall_s, d.steps));
  }
  if (std::find(d.pending.begin(), d.pending.end(), 1) != d.pending.end()) {
    for (size_t g = 0; g < d.pending.size(); ++g)
      if (d.pending[g]) d.ws.gate_on[g] = !d.ws.gate_on[g], d.pending[g] = 0;
    d.flipped = true;
    gsl_odeiv2_evolve_reset(d.evolve.get());
  }
  const size_t ng = m.gates.size();
  const bool stop_at_q = std::isfinite(q_stop);
  double t = d.ws.t;
  const double t_prev = t, y_prev[3] = {d.y[0], d.y[1], d.y[2]};
  // The previous step's end is this step's start (same state, same gates) unless a gate
  // flipped or the integrator was reset.
  if (!(d.end.t == t_prev && d.end.q == y_prev[0] && d.end.qdot == y_prev[1] && !d.flipped)) {
    d.start = d.point(t_prev, y_prev);
    for (size_t g = 0; g < ng; ++g) d.s_before[g] = calc_switching(m, static_cast<int>(g), d.y[0], d.y[1]);
  } else {
    d.start = d.end;
    d.s_before = d.s_after;
  }
  d.flipped = false;
  const double stop_before = stop_at_q ? y_prev[0] - q_stop : 0.0;
  const int st = d.evolve_apply(&t, t_end, &d.h, d.y);
  if (st != GSL_SUCCESS)
    throw models::NumericalError(fmt::format("reduced integration failed at t = {:.6g} s (q = {:.9g}, q̇ = {:.6g}): "
                                             "{}",
                                             t_prev, y_prev[0], y_prev[1], describe_gsl_failure(st, d.h)));
  ++d.steps;
  d.end = d.end_point(t, d.y);  // the raw step's end (Hermite needs it for event estimates)
  // What changed sign in this step: a gate's switching function (index ≥ 0) or q − q_stop (−2).
  // The earliest crossing, located on single steps from the start of the step, ends the step.
  const double H = t - t_prev;
  Impl::Cut cut;
  cut.h = INFINITY;
  int which = -1;
  for (size_t g = 0; g < ng; ++g) {
    d.s_after[g] = calc_switching(m, static_cast<int>(g), d.y[0], d.y[1]);
    if (d.s_before[g] == 0.0 || (d.s_before[g] > 0) == (d.s_after[g] > 0)) continue;
    const auto c = d.locate([&](double q, double v) { return calc_switching(m, static_cast<int>(g), q, v); },
                            t_prev, y_prev, H, d.s_before[g], d.s_after[g]);
    if (c.h < cut.h) cut = c, which = static_cast<int>(g);
  }
  if (stop_at_q && stop_before != 0.0 && (stop_before > 0) != (d.y[0] - q_stop > 0)) {
    const auto c = d.locate([&](double q, double) { return q - q_stop; }, t_prev, y_prev, H, stop_before,
                            d.y[0] - q_stop);
    if (c.h <= cut.h) cut = c, which = -2;
  }
  if (which != -1) {
    for (int k = 0; k < 3; ++k) d.y[k] = cut.y[k];
    t = t_prev + cut.h;
    gsl_odeiv2_evolve_reset(d.evolve.get());
    d.end = d.point(t, d.y);
    // Every gate whose switching function has changed sign by the cut flips — several do at
    // once when q̇ itself crosses zero (the crank stalls and turns back) — and when the step
    // stops at q_stop on a switch angle, whose cut lies past both crossings (a lost flip left
    // the gate disagreeing with its witness, and the next steps chattered without end).
    for (size_t g = 0; g < ng; ++g) {
      d.s_after[g] = calc_switching(m, static_cast<int>(g), d.y[0], d.y[1]);
      if (d.s_before[g] != 0.0 && (d.s_before[g] > 0) != (d.s_after[g] > 0)) {
        d.pending[g] = 1;
        ++d.events;
      }
    }
  } else if (t < t_end) {
    d.smallest = std::min(d.smallest, H);
  }
  d.ws.q = d.y[0], d.ws.qdot = d.y[1], d.ws.work = d.y[2], d.ws.t = t;
  if (!std::isfinite(d.ws.q) || !std::isfinite(d.ws.qdot) || !std::isfinite(d.ws.work))
    throw models::NumericalError(fmt::format("reduced model produced a non-finite state at t = {:.6g} s", t));
  if (!m.table.in_range(d.ws.q)) {
    // The edge of a range table: locate the crossing like an event (for the message), then stop.
    const double edge = domain_edge(m, d.ws.q);
    const auto c = d.locate([&](double q, double) { return q - edge; }, t_prev, y_prev, H, y_prev[0] - edge,
                            d.ws.q - edge);
    throw_left_domain(m, edge, t_prev + c.h);
  }
  // A cut at a switch located just before q_stop may lie past q_stop too (q_stop on a switch
  // angle): that is the stop, or every later step would start beyond it and never stop.
  return which == -2 || (which >= 0 && stop_at_q && stop_before != 0.0 && (stop_before > 0) != (d.y[0] - q_stop > 0));
}

bool AdaptiveIntegrator::advance(double t_end, double q_stop) {
  while (impl_->ws.t < t_end)
    if (step(t_end, q_stop)) return true;
  return false;
}

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
    if (!step_type(opt.integrator))
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
    throw TableError(fmt::format("reduced simulation start q = {:.9g} lies outside the range [{:.9g}, {:.9g}] of its "
                                 "table (rad or m)",
                                 q0, m.table.q0, m.table.q0 + m.table.intervals * m.table.step));
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
      else hermite(a, b, s, q, v, w);
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
        hermite(a, b, (grid.t(i) - a.t) / (b.t - a.t), q, v, w);
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
  throw models::NumericalError(fmt::format(
      "reduced model's energy balance does not close: max|E − E0 − W| = {:.3g} J at t = {:.6g} s is {:.3g} % of the "
      "energy scale {:.3g} J (largest |E|, |W| or range of E; limit {:g} %): the integration lost or invented energy "
      "({}; try a shorter fixed step or an adaptive integrator)",
      eb.max_residual_J, eb.worst_time_s, 100 * eb.max_residual_J / std::max(scale_J, 1e-300), scale_J,
      100 * tolerance, how));
}

}  // namespace rdyn::reduced
