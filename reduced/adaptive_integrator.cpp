// Adaptive GSL odeiv2 integration of the reduced model with load switches located as events
// (reduced/adaptive_integrator.hpp).
#include "reduced/adaptive_integrator.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

namespace rdyn::reduced {

namespace {

const gsl_odeiv2_step_type* gsl_step_type(const std::string& name) {
  if (name == "rk8pd") return gsl_odeiv2_step_rk8pd;
  if (name == "rkf45") return gsl_odeiv2_step_rkf45;
  if (name == "rkck") return gsl_odeiv2_step_rkck;
  return nullptr;
}

}  // namespace

bool is_adaptive_method(const std::string& name) { return gsl_step_type(name) != nullptr; }

// Quintic Hermite through (q, q̇, q̈) at both ends of a step of length H, at fraction s;
// cubic Hermite for W through (W, P). q̈ at the sample is recomputed from the model.
void calc_hermite(const AdaptiveIntegrator::Point& a, const AdaptiveIntegrator::Point& b, double s, double& q,
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

// The edge of a range table's validity domain that q has crossed.
double calc_gate_window_fraction(const ReducedModel& m, int g, double q0, double q1) {
  const auto& roots = m.gates[g].roots;
  if (roots.empty() || !(q1 != q0) || !std::isfinite(q0) || !std::isfinite(q1)) return 1.0;
  const double lo = std::min(q0, q1), hi = std::max(q0, q1);
  const double P = m.table.periodic ? m.table.period : 0.0;
  // The switch angles strictly inside (lo, hi), every turn's copy of them on a periodic table.
  std::vector<double> inside;
  for (double r : roots) {
    if (P > 0) {
      for (double k = std::ceil((lo - r) / P); r + k * P < hi && inside.size() < 64; k += 1.0)
        if (r + k * P > lo) inside.push_back(r + k * P);
    } else if (r > lo && r < hi) {
      inside.push_back(r);
    }
  }
  if (inside.size() < 2) return 1.0;
  std::sort(inside.begin(), inside.end());
  // The first two in the direction of motion bound the first window.
  const double a = q1 > q0 ? inside[0] : inside[inside.size() - 1];
  const double b = q1 > q0 ? inside[1] : inside[inside.size() - 2];
  return (0.5 * (a + b) - q0) / (q1 - q0);
}

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
      describe_q(m.revolute, edge),
      kind.empty() ? "edge of the table" : kind, t));
}

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


template <typename T, void (*F)(T*)>
struct Deleter {
  void operator()(T* p) const { F(p); }
};


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
  double window_t0 = 0.0;  // time at the start of the current window of kWindow accepted steps

  Impl(const ReducedModel& model, double tol, const std::string& method, IntegratorLimits lim)
      : m(model), ws(model), ctx{&m, &ws}, limits(lim) {
    const gsl_odeiv2_step_type* type = gsl_step_type(method);
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
  // Budgets: every run ends, in steps and in wall time (the clock is read every 64 steps); a run
  // that cannot finish fails early (NumericalError).
  void check_budgets(double t_end) {
    const long attempted = steps + static_cast<long>(evolve->failed_steps);
    if (attempted >= limits.max_steps)
      throw models::NumericalError(fmt::format(
          "reduced integration stopped at t = {:.6g} s: it used its budget of {} steps (the run needs more; "
          "loosen the tolerance or shorten the duration)",
          ws.t, limits.max_steps));
    // Hopeless runs fail early, as the full model's (engine/forward_dynamics.cpp, check_budgets):
    // every kWindow accepted steps, the steps still needed to reach t_end at the window's mean step;
    // more than kHopeless budgets will not finish. A motor stalled against a rate-gated load
    // chatters at the gate's switch with steps of ~1e-13 s: the full model stopped in 5 s, the
    // reduced one ran for minutes (issue #23's shaper).
    constexpr long kWindow = 1000;
    constexpr double kHopeless = 100.0;
    // A window of steps that left t where it was (cuts at a gate chattering at a standstill, each
    // below t's ulp) is as hopeless: it was not counted, and a Jansen leg stalled against a backstop
    // gate ran 8 minutes to its step budget, whose message blamed the tolerance.
    if (steps > 0 && steps % kWindow == 0 && ws.t == window_t0)
      throw models::NumericalError(fmt::format(
          "reduced integration stopped at t = {:.6g} s of {:.6g} s ({}, q̇ = {:.3g} {}): its last {} steps did not "
          "advance the time: the motion is too stiff or too fast (a load switching back and forth at a standstill, a "
          "stalled drive)",
          ws.t, t_end, describe_q(m.revolute, ws.q), ws.qdot, m.revolute ? "rad/s" : "m/s", kWindow));
    if (steps > 0 && steps % kWindow == 0 && ws.t != window_t0) {
      const double mean_h = (ws.t - window_t0) / kWindow;
      const double needed = static_cast<double>(attempted) + (t_end - ws.t) / std::max(mean_h, 1e-300);
      window_t0 = ws.t;
      if (needed > kHopeless * static_cast<double>(limits.max_steps))
        throw models::NumericalError(fmt::format(
            "reduced integration stopped at t = {:.6g} s of {:.6g} s: at its mean step of the last {} steps ({:.3g} s) "
            "it would need ~{:.3g} steps, more than {:g} × the step budget of {}: the motion is too stiff or too fast "
            "(a load switching back and forth at a standstill, a stalled drive)",
            ws.t, t_end, kWindow, mean_h, needed, kHopeless, limits.max_steps));
    }
    if (steps % 64 == 0) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      if (wall > limits.max_wall_s)
        throw models::NumericalError(fmt::format(
            "reduced integration stopped at t = {:.6g} s: it used its wall-time budget of {:g} s after {} steps",
            ws.t, limits.max_wall_s, steps));
    }
  }

  // After a successful step from (t_prev, y_prev) to (t, y): returns the GSL status of the step
  // finally kept.
  int retake_over_gate_window(double t_prev, const double y_prev[3], double& t) {
    const size_t ng = m.gates.size();
    // A gate window the step passed whole (q crossed two switch angles, so the switching function
    // has one sign at both ends) is not seen by its sign: the step is taken again to the middle of
    // the window (linear in q; again while it still passes one, at most kWindowRetries times), so
    // that its end lies inside and the crossing is located below. A five-bar's gate on a joint
    // that turns the gated way over 8° of the crank (5–20 ms a turn) was stepped over every turn
    // by the default 1e-8 rk8pd: 26 switches against the full model's 28, its forces 60 % off.
    constexpr int kWindowRetries = 8;
    int st = GSL_SUCCESS;
    for (int k = 0; k < kWindowRetries && st == GSL_SUCCESS && y_prev[1] * y[1] > 0; ++k) {
      double f = 1.0;
      for (size_t g = 0; g < ng; ++g) {
        const double after = calc_switching(m, static_cast<int>(g), y[0], y[1]);
        if (s_before[g] != 0.0 && (s_before[g] > 0) == (after > 0))
          f = std::min(f, calc_gate_window_fraction(m, static_cast<int>(g), y_prev[0], y[0]));
      }
      if (!(f > 0.0 && f < 1.0)) break;
      const double h_try = (t - t_prev) * f;
      if (!(t_prev + h_try > t_prev)) break;
      t = t_prev;
      for (int j = 0; j < 3; ++j) y[j] = y_prev[j];
      double h_step = h_try;
      st = evolve_apply(&t, t_prev + h_try, &h_step, y);
      h = std::min(h, h_step);
    }
    return st;
  }

  struct Cut {
    double h = 0.0;
    double y[3] = {0, 0, 0};
  };
  template <typename G>
  Cut locate(G&& g, double t0, const double y0[3], double H, double g0, double gH) {
    const double tol = 1e-13 * std::max(1.0, std::abs(t0));
    auto on_hermite = [&](double hh) {
      double q, v, w;
      calc_hermite(start, end, hh / H, q, v, w);
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
  d.window_t0 = t;
  gsl_odeiv2_evolve_reset(d.evolve.get());
}

bool AdaptiveIntegrator::step(double t_end, double q_stop) {
  auto& d = *impl_;
  const auto& m = d.m;
  d.check_budgets(t_end);
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
  int st = d.evolve_apply(&t, t_end, &d.h, d.y);
  if (st == GSL_SUCCESS) st = d.retake_over_gate_window(t_prev, y_prev, t);
  if (st != GSL_SUCCESS)
    throw models::NumericalError(fmt::format("reduced integration failed at t = {:.6g} s ({}, q̇ = {:.6g} {}): {}",
                                             t_prev, describe_q(m.revolute, y_prev[0]), y_prev[1],
                                             m.revolute ? "rad/s" : "m/s", describe_gsl_failure(st, d.h)));
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

}  // namespace rdyn::reduced
