#include "reduced/steady_cycle.hpp"
#include "reduced/cycle_extremes.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "reduced/simulate_reduced.hpp"

namespace rdyn::reduced {

std::string cycle_method_name(CycleMethod m) {
  return m == CycleMethod::FirstIntegral ? "first-integral" : "time-stepping";
}

void check_steady_cycle_options(const SteadyCycleOptions& o) {
  if (!std::isfinite(o.q_section))
    throw TableError(fmt::format("steady cycle: the section q = {} must be finite", o.q_section));
  if (!(std::isfinite(o.qdot_guess) && o.qdot_guess != 0.0))
    throw TableError(fmt::format("steady cycle: the first guess of q̇ ({} rad/s) must be finite and non-zero (its "
                                 "sign is the direction of the cycle)",
                                 o.qdot_guess));
  if (!(o.tolerance >= kMinTolerance && o.tolerance <= kMaxTolerance))
    throw TableError(fmt::format("steady cycle: tolerance {:g} is out of range [{:g}, {:g}]", o.tolerance,
                                 kMinTolerance, kMaxTolerance));
  if (!(o.samples >= kMinCycleSamples && o.samples <= kMaxCycleSamples))
    throw TableError(fmt::format("steady cycle: {} samples per cycle is out of range [{}, {}]", o.samples,
                                 kMinCycleSamples, kMaxCycleSamples));
  if (!(o.max_passes >= 1 && o.max_passes <= kMaxCyclePasses))
    throw TableError(fmt::format("steady cycle: {} passes is out of range [1, {}]", o.max_passes, kMaxCyclePasses));
}

namespace {

// Relative size of the fixed-point residual |Φ(u) − u| / u at which the cycle is accepted
// (a few hundred ulps: the map is smooth in u, so the secant reaches it), and the looser one
// accepted when the search stagnates there (as the former time-stepping calibration did).
constexpr double kFixedPointTolerance = 1e-12;
constexpr double kFixedPointStagnation = 1e-9;

// Quantities followed over the cycle at each point: |q̇|, −|q̇| (its minimum as a maximum),
// then |F_E,k| per constraint force.
int quantity_count(const ReducedModel& m) { return 2 + static_cast<int>(m.force_names.size()); }

// Followed quantities at a state (q, q̇) with the workspace's gates.
void quantities_at(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, std::vector<double>& forces,
                   double* out) {
  double qdd, p;
  calc_sample(m, ws, q, qdot, qdd, p, forces.data());  // the path simulate_reduced's outputs take
  out[0] = std::abs(qdot);
  out[1] = -std::abs(qdot);
  for (size_t k = 0; k < forces.size(); ++k) out[2 + k] = std::abs(forces[k]);
}

// Power of the resistances at (q, q̇) [W]: Σ T_b(w_b q̇)·w_b q̇.
double brake_power(const ReducedModel& m, double q, double qdot) {
  double p = 0.0;
  for (const auto& b : m.brakes) {
    const double w = m.table.eval(b.c_w, q);
    p += models::resistance_torque(b.law, b.coefficient, w * qdot) * w * qdot;
  }
  return p;
}

// Zeros of column `col` of the table's cubics inside [q0, q0 + P): the extremes of each cubic
// split its interval into monotone pieces, each bisected where it changes sign.
void column_zeros(const Table& t, int col, std::vector<double>& zeros) {
  for (int iv = 0; iv < t.intervals; ++iv) {
    const double* c = &t.coef[(static_cast<size_t>(iv) * t.cols + col) * 4];
    auto f = [&](double x) { return c[0] + x * (c[1] + x * (c[2] + x * c[3])); };
    double cuts[4] = {0.0, 0.0, 0.0, t.step};
    int nc = 1;
    // Extremes: c1 + 2 c2 x + 3 c3 x² = 0.
    const double A = 3 * c[3], B = 2 * c[2], C = c[1];
    if (A != 0.0) {
      const double disc = B * B - 4 * A * C;
      if (disc > 0) {
        const double sq = std::sqrt(disc);
        for (double x : {(-B - sq) / (2 * A), (-B + sq) / (2 * A)})
          if (x > 0 && x < t.step) cuts[nc++] = x;
      }
    } else if (B != 0.0) {
      const double x = -C / B;
      if (x > 0 && x < t.step) cuts[nc++] = x;
    }
    cuts[nc++] = t.step;
    std::sort(cuts, cuts + nc);
    for (int p = 0; p + 1 < nc; ++p) {
      double lo = cuts[p], hi = cuts[p + 1], flo = f(lo), fhi = f(hi);
      if (flo == 0.0 && p == 0) zeros.push_back(t.q0 + iv * t.step);
      if (!((flo < 0 && fhi > 0) || (flo > 0 && fhi < 0))) continue;
      for (int it = 0; it < 200 && hi - lo > 1e-15 * std::max(1.0, std::abs(hi)); ++it) {
        const double mid = 0.5 * (lo + hi), fm = f(mid);
        if ((fm > 0) == (flo > 0)) lo = mid, flo = fm;
        else hi = mid;
      }
      zeros.push_back(t.q0 + iv * t.step + 0.5 * (lo + hi));
    }
  }
}

template <typename T, void (*F)(T*)>
struct Deleter {
  void operator()(T* p) const { F(p); }
};

// The first-integral integration over one period: state y = (u, t, W, W_b) as functions of
// θ = s·(q − q_s) ∈ [0, P] (increasing whatever the direction s), with
//   du/dθ = s·q̈(q, s√(2u)),  dt/dθ = 1/√(2u),  dW/dθ = P_nc/√(2u),  dW_b/dθ = P_b/√(2u)
// (W: work of every non-conservative load, W_b: of the resistances). Segments end at every
// switch angle (the gates are constant inside a segment) and, on coarse tables (≥ 1°, where
// linear and Akima columns have kinks at the knots), at every knot. Inside a segment rk8pd
// steps with the usual error control (u relative to u, t relative to the step's own
// duration); later passes replay the first pass's step grid, so that the map u ↦ Φ(u) is
// smooth as the secant needs, and adapt again only where the replayed error exceeds the
// tolerance.
struct FirstIntegral {
  const ReducedModel& m;
  ReducedWorkspace ws;
  double qs, s, P, tol;
  long evals = 0, steps = 0;
  std::vector<double> a, b;  // segment ends in θ
  std::vector<char> gates;   // [segment][gate]
  struct Step {
    double th, h;
    int seg;
  };
  std::vector<Step> grid;      // accepted steps of the last pass
  std::vector<int> seg_first;  // first step of each segment (and the step count at the end)
  std::vector<double> ys;      // state at each step's start [step][4], of the last pass
  double y_end[4] = {0, 0, 0, 0};
  double stall_theta = 0.0;
  double h_guess = 0.0;
  gsl_odeiv2_system sys;
  std::unique_ptr<gsl_odeiv2_step, Deleter<gsl_odeiv2_step, gsl_odeiv2_step_free>> stepper;

  static int rhs(double theta, const double y[], double f[], void* params) {
    auto& c = *static_cast<FirstIntegral*>(params);
    ++c.evals;
    const double u = y[0];
    if (!(u > 0) || !std::isfinite(u)) return GSL_EBADFUNC;  // q̇ reached zero: no cycle of this sign
    const double q = c.qs + c.s * theta, speed = std::sqrt(2 * u), qdot = c.s * speed;
    double qdd, power;
    calc_acceleration(c.m, c.ws, q, qdot, qdd, power);  // Eksergian: m1 q̈ + m2 q̇² = F*
    f[0] = c.s * qdd;                                   // du/dθ = s·du/dq = s·q̈
    f[1] = 1.0 / speed;                                 // dt/dθ = 1/|q̇|
    f[2] = power / speed;
    f[3] = brake_power(c.m, q, qdot) / speed;
    return std::isfinite(f[0]) && std::isfinite(f[2]) && std::isfinite(f[3]) ? GSL_SUCCESS : GSL_EBADFUNC;
  }

  FirstIntegral(const ReducedModel& model, const SteadyCycleOptions& opt)
      : m(model),
        ws(model),
        qs(opt.q_section),
        s(opt.qdot_guess > 0 ? 1.0 : -1.0),
        P(model.table.period),
        tol(opt.tolerance) {
    gsl_set_error_handler_off();
    sys = {rhs, nullptr, 4, this};
    stepper.reset(gsl_odeiv2_step_alloc(gsl_odeiv2_step_rk8pd, 4));
    // Breakpoints in q: gate switch angles (the exact roots when the table has them, else the
    // zeros of the interpolated ratio), the zeros of w for resistances of constant magnitude
    // (their sign follows w·q̇), and the knots of a coarse table.
    const Table& t = m.table;
    std::vector<double> qb;
    if (t.intervals <= 360)
      for (int i = 0; i < t.intervals; ++i) qb.push_back(t.q0 + i * t.step);
    for (const auto& g : m.gates) {
      if (!g.roots.empty()) qb.insert(qb.end(), g.roots.begin(), g.roots.end());
      else column_zeros(t, g.c_r, qb);
    }
    for (const auto& br : m.brakes)
      if (br.law == models::ResistanceLaw::Constant) column_zeros(t, br.c_w, qb);
    std::vector<double> th{0.0};
    for (double q : qb) {
      double x = s * (q - qs);
      x -= P * std::floor(x / P);
      if (x > 0 && x < P) th.push_back(x);
    }
    std::sort(th.begin(), th.end());
    const double merge = 1e-12 * P;  // a switch angle on a knot is one breakpoint
    for (double x : th)
      if (x < P - merge && (a.empty() || x - a.back() > merge)) a.push_back(x);
    for (size_t j = 0; j < a.size(); ++j) b.push_back(j + 1 < a.size() ? a[j + 1] : P);
    const size_t ng = m.gates.size();
    gates.assign(a.size() * ng, 0);
    for (size_t j = 0; j < a.size(); ++j)
      for (size_t g = 0; g < ng; ++g)
        gates[j * ng + g] = calc_switching(m, static_cast<int>(g), qs + s * 0.5 * (a[j] + b[j]), s) > 0;
    h_guess = std::min(P / 64, b[0] - a[0]);
  }

  void set_gates(size_t j) {
    const size_t ng = m.gates.size();
    for (size_t g = 0; g < ng; ++g) ws.gate_on[g] = gates[j * ng + g];
  }

  // One rk8pd step of segment j from θ (state y, updated). Returns its error estimate relative
  // to the tolerance; +∞ when a stage failed (q̇ reached zero, a non-finite value).
  double apply(size_t j, double theta, double h, double y[4]) {
    set_gates(j);
    double err[4];
    const double t_before = y[1];
    ++steps;
    if (gsl_odeiv2_step_apply(stepper.get(), theta, h, y, err, nullptr, nullptr, &sys) != GSL_SUCCESS ||
        !(y[0] > 0) || !std::isfinite(y[1]) || !std::isfinite(y[2]) || !std::isfinite(y[3]))
      return INFINITY;
    return std::max(std::abs(err[0]) / (tol * y[0]), std::abs(err[1]) / (tol * (y[1] - t_before)));
  }

  // A pass stalls where u falls below kStallFraction of the largest u it has seen (q̇ below
  // 1e-4 of its peak): u → 0 makes dt/dθ = 1/√(2u) singular, and the steps would shrink without
  // end approaching the stop.
  static constexpr double kStallFraction = 1e-8;
  double u_peak = 0.0;
  bool stalled(double u) {
    u_peak = std::max(u_peak, u);
    return u < kStallFraction * u_peak;
  }

  // One period from u0 at θ = 0 with error control, recording the step grid. Returns false on
  // a stall (u below kStallFraction of its peak, a step below 1e-12 P that still misses the
  // tolerance, or a budget of 5·10⁴ attempted steps used up — the bicycle's pass takes ~100);
  // stall_theta: where.
  bool adapt_pass(double u0) {
    grid.clear(), ys.clear(), seg_first.clear();
    double y[4] = {u0, 0.0, 0.0, 0.0};
    double h = h_guess;
    long attempts = 0;
    u_peak = u0;
    for (size_t j = 0; j < a.size(); ++j) {
      seg_first.push_back(static_cast<int>(grid.size()));
      double th = a[j];
      while (th < b[j]) {
        const bool last = th + h >= b[j] - 1e-9 * (b[j] - a[j]);
        const double hh = last ? b[j] - th : h;
        double yy[4] = {y[0], y[1], y[2], y[3]};
        const double err = apply(j, th, hh, yy);
        // rk8pd's error ∝ h⁸: the step that meets the tolerance (factor 0.9, growth ≤ 5).
        const double factor = err > 0 ? 0.9 * std::pow(err, -1.0 / 8) : 5.0;
        if (++attempts > 50000 || (err > 1.0 && hh < 1e-12 * P) || (err <= 1.0 && stalled(yy[0]))) {
          stall_theta = th;
          grid.clear();  // the next pass adapts afresh
          return false;
        }
        if (err > 1.0) {
          h = hh * std::max(0.2, std::isfinite(factor) ? factor : 0.2);
          continue;
        }
        grid.push_back({th, hh, static_cast<int>(j)});
        ys.insert(ys.end(), y, y + 4);
        std::copy(yy, yy + 4, y);
        th = last ? b[j] : th + hh;
        const double h_next = hh * std::min(5.0, factor);
        if (!last || h_next < h) h = h_next;  // a short last step does not shrink the next segment's
      }
    }
    seg_first.push_back(static_cast<int>(grid.size()));
    std::copy(y, y + 4, y_end);
    h_guess = std::min(P / 64, b[0] - a[0]);
    return true;
  }

  // One period from u0 on the last pass's step grid; adapts afresh when a replayed step
  // misses the tolerance (or there is no grid yet).
  bool pass(double u0) {
    if (grid.empty()) return adapt_pass(u0);
    double y[4] = {u0, 0.0, 0.0, 0.0};
    u_peak = u0;
    for (size_t i = 0; i < grid.size(); ++i) {
      std::copy(y, y + 4, &ys[4 * i]);
      if (!(apply(grid[i].seg, grid[i].th, grid[i].h, y) <= 1.0) || stalled(y[0])) return adapt_pass(u0);
    }
    std::copy(y, y + 4, y_end);
    return true;
  }

  // State at θ inside segment j on the last pass: from the start of the step containing θ,
  // one step of the remaining length (the segment's end: the next segment's start).
  void state_at(size_t j, double theta, double y[4]) {
    const int lo = seg_first[j], hi = seg_first[j + 1];
    if (theta >= b[j]) {
      const double* src = hi < static_cast<int>(grid.size()) ? &ys[4 * hi] : y_end;
      std::copy(src, src + 4, y);
      return;
    }
    // The last step of the segment starting at or before θ.
    const auto it = std::upper_bound(grid.begin() + lo, grid.begin() + hi, theta,
                                     [](double x, const Step& st) { return x < st.th; });
    const int i = std::max(lo, static_cast<int>(it - grid.begin()) - 1);
    std::copy(&ys[4 * i], &ys[4 * i] + 4, y);
    if (theta > grid[i].th) apply(j, grid[i].th, theta - grid[i].th, y);
  }

  // du/dθ at both ends of every step of the last pass (its segment's gates): two right-hand
  // sides per step, against state_at's thirteen per point.
  std::vector<double> slope_start, slope_end;
  void prepare_scan() {
    slope_start.resize(grid.size()), slope_end.resize(grid.size());
    for (size_t i = 0; i < grid.size(); ++i) {
      set_gates(grid[i].seg);
      const double* y1 = i + 1 < grid.size() ? &ys[4 * (i + 1)] : y_end;
      double f[4] = {0, 0, 0, 0};
      rhs(grid[i].th, &ys[4 * i], f, this);
      slope_start[i] = f[0];
      rhs(grid[i].th + grid[i].h, y1, f, this);
      slope_end[i] = f[0];
    }
  }

  // u at θ inside segment j by the cubic Hermite interpolant of the step containing θ (u and
  // du/dθ at its ends; error ~h⁴·u''''/384, ~1e-8 of u on the bicycle's steps of ~3.6°): where
  // the extremes' scan looks, not what it returns (state_at refines). After prepare_scan.
  double u_scan(size_t j, double theta) const {
    const int lo = seg_first[j], hi = seg_first[j + 1];
    const auto it = std::upper_bound(grid.begin() + lo, grid.begin() + hi, theta,
                                     [](double x, const Step& st) { return x < st.th; });
    const int i = std::max(lo, static_cast<int>(it - grid.begin()) - 1);
    const double h = grid[i].h, t = std::clamp((theta - grid[i].th) / h, 0.0, 1.0);
    const double u0 = ys[4 * i], u1 = i + 1 < static_cast<int>(grid.size()) ? ys[4 * (i + 1)] : y_end[0];
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * u0 + (t3 - 2 * t2 + t) * h * slope_start[i] + (3 * t2 - 2 * t3) * u1 +
           (t3 - t2) * h * slope_end[i];
  }
};

void check_finite(const SteadyCycle& c, const char* method) {
  bool ok = std::isfinite(c.period_s) && c.period_s > 0 && std::isfinite(c.qdot_section) &&
            std::isfinite(c.speed_min) && std::isfinite(c.speed_max) && std::isfinite(c.drive_work_J) &&
            std::isfinite(c.dissipated_work_J);
  for (double f : c.peak_force_N) ok = ok && std::isfinite(f);
  if (!ok) throw models::NumericalError(fmt::format("steady cycle ({}): a result is not finite", method));
}

void fill_work(SteadyCycle& c, double P, double work_nc, double work_brakes) {
  c.mean_cadence_hz = 1.0 / c.period_s;
  c.drive_work_J = work_nc - work_brakes;
  c.dissipated_work_J = -work_brakes;
  c.drive_power_W = c.drive_work_J / c.period_s;
  c.dissipated_power_W = c.dissipated_work_J / c.period_s;
  c.speed_fluctuation = (c.speed_max - c.speed_min) / (P / c.period_s);
}

// Whether the last pass closes the cycle: u returns to itself to `rel`, and the kinetic energy
// it gains or loses per cycle, m1(q_s)·(Φ(u) − u), is below 1e-6 of the work flowing through
// the cycle (drive plus dissipation). The second test refuses a runaway (a drive with nothing
// to dissipate it: the speed grows by the same Δu every cycle, which the relative test alone
// would accept once u is large enough); a cycle without non-conservative work (every start is
// periodic) passes on the first.
bool closes(const FirstIntegral& fi, double g, double u, double rel) {
  if (!(std::abs(g) <= rel * u)) return false;
  const double work_brakes = fi.y_end[3], work_drive = fi.y_end[2] - fi.y_end[3];
  const double flow = std::abs(work_drive) + std::abs(work_brakes);
  if (flow == 0.0) return true;
  // m1·u: the kinetic energy at q_s. Beyond 1e7 times the flow, a gain of 1e-6 of the flow is
  // below the rounding of u (1e-16 of it): the test could not tell a runaway from a cycle.
  const double m1 = fi.m.table.eval(fi.m.c_m1, fi.qs);
  return m1 * std::abs(g) <= 1e-6 * flow && m1 * u <= 1e7 * flow;
}

}  // namespace

SteadyCycle calc_steady_cycle(const ReducedModel& m, const SteadyCycleOptions& opt) {
  check_steady_cycle_options(opt);
  if (!m.table.periodic)
    throw models::NumericalError("steady cycle: the table is not periodic (the independent coordinate does not turn "
                                 "a full period), so there is no cycle");
  FirstIntegral fi(m, opt);
  const double P = fi.P;
  // Secant on g(u) = Φ(u) − u, safeguarded by the bracket (lo, hi) the passes establish:
  // solutions u(θ) of the first-order equation cannot cross, so Φ is increasing, and a start
  // that stalls lies below every start that completes the period.
  double u = 0.5 * opt.qdot_guess * opt.qdot_guess;
  double lo = 0.0, hi = INFINITY, u_prev = 0.0, g_prev = 0.0, g = INFINITY;
  double u_ok = NAN, g_ok = INFINITY;  // the last pass that completed the period
  double g_hi = 0.0;                    // Φ(hi) − hi
  bool lo_stalls = false;               // lo is a start that stalls
  bool have_prev = false, any_pass = false, converged = false;
  int passes = 0;
  double stall_q = NAN;
  while (passes < opt.max_passes) {
    ++passes;
    if (!fi.pass(u)) {
      stall_q = opt.q_section + fi.s * fi.stall_theta;
      lo = std::max(lo, u);
      lo_stalls = true;
      have_prev = false;
      // A fixed point u* lies above every start that stalls, and Φ is increasing, so at the
      // start hi: Φ(hi) − hi ≥ u* − hi > lo − hi. A start that loses more than hi − lo over the
      // period proves there is none.
      if (std::isfinite(hi) && g_hi <= lo - hi) break;
      u = std::isfinite(hi) ? 0.5 * (lo + hi) : 4 * u;
      if (!std::isfinite(u)) break;
      continue;
    }
    any_pass = true;
    g = fi.y_end[0] - u;
    u_ok = u, g_ok = g;
    if (closes(fi, g, u, kFixedPointTolerance)) {
      converged = true;
      break;
    }
    if (g > 0) {
      lo = std::max(lo, u);
      lo_stalls = false;
    } else if (u < hi) {
      hi = u, g_hi = g;
      if (lo_stalls && g_hi <= lo - hi) break;  // as above
    }
    double next = have_prev && g != g_prev ? u - g * (u - u_prev) / (g - g_prev) : u + g;
    if (!(next > lo && next < hi)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : 2 * std::max(u, lo);
    if (!std::isfinite(next)) break;
    u_prev = u, g_prev = g, have_prev = true;
    if (next == u) break;  // the bracket has shrunk to rounding
    u = next;
  }
  if (!converged) {
    // Stagnation just above the target: the last pass is the cycle if it closed to 1e-9.
    if (any_pass && std::abs(g_ok) <= kFixedPointStagnation * u_ok && fi.pass(u_ok) &&
        closes(fi, fi.y_end[0] - u_ok, u_ok, kFixedPointStagnation)) {
      u = u_ok;
    } else {
      if (!any_pass)
        throw models::NumericalError(fmt::format(
            "steady cycle: q̇ reaches zero (near q = {:.6g}°) from every start speed tried, up to {:.6g} rad/s: no "
            "cycle with q̇ of one sign (the mechanism stalls or turns back)",
            stall_q * 180 / M_PI, std::sqrt(2 * lo)));
      throw models::NumericalError(fmt::format(
          "steady cycle: no cycle with q̇ of one sign found in {} passes (from q̇ = {:.6g} rad/s at the section the "
          "kinetic energy still changes by {:.3g} J per cycle{})",
          passes, fi.s * std::sqrt(2 * u_ok), m.table.eval(m.c_m1, opt.q_section) * g_ok,
          std::isfinite(stall_q) ? fmt::format("; slower starts stall near q = {:.6g}°", stall_q * 180 / M_PI) : ""));
    }
  }
  SteadyCycle c;
  c.method = CycleMethod::FirstIntegral;
  c.passes = passes;
  c.qdot_section = fi.s * std::sqrt(2 * u);
  c.period_s = fi.y_end[1];
  const double work_nc = fi.y_end[2], work_brakes = fi.y_end[3];
  // Extremes of |q̇| and |F_E| over the cycle: every segment sampled, the best refined.
  if (opt.extremes) {
    std::vector<double> forces(m.force_names.size()), value, where;
    fi.prepare_scan();
    find_extremes(
        fi.a, fi.b, opt.samples, P, quantity_count(m),
        [&](int j, double theta, double* out) {
          fi.set_gates(j);
          const double u = fi.u_scan(j, theta);
          quantities_at(m, fi.ws, opt.q_section + fi.s * theta, fi.s * std::sqrt(2 * std::max(u, 0.0)), forces, out);
        },
        [&](int j, double theta, double* out) {
          double y[4];
          fi.state_at(j, theta, y);
          fi.set_gates(j);
          quantities_at(m, fi.ws, opt.q_section + fi.s * theta, fi.s * std::sqrt(2 * y[0]), forces, out);
        },
        value, where);
    c.speed_max = value[0];
    c.speed_min = -value[1];
    for (size_t k = 0; k < forces.size(); ++k) {
      c.peak_force_N.push_back(value[2 + k]);
      const double q = opt.q_section + fi.s * where[2 + k];
      c.peak_force_q.push_back(q - P * std::floor((q - m.table.q0) / P));
    }
  } else {
    c.speed_min = c.speed_max = std::abs(c.qdot_section);
  }
  fill_work(c, P, work_nc, work_brakes);
  c.steps = fi.steps;
  c.rhs_evaluations = fi.evals;
  check_finite(c, "first integral");
  return c;
}

namespace {

// The fixed point of the Poincaré map at the section q_s (time stepping): the section speed, the
// period, and the revolutions and steps it took.
struct SectionSpeed {
  double qdot = NAN, period_s = NAN;
  int passes = 0;
  long steps = 0;
};

// Secant iteration on g(v) = Φ(v) − v, Φ(v) the q̇ after one period from (q_s, v); NumericalError
// when it finds no cycle.
SectionSpeed find_section_speed(const ReducedModel& m, const SteadyCycleOptions& opt) {
  const double s = opt.qdot_guess > 0 ? 1.0 : -1.0, P = m.table.period, qs = opt.q_section;
  // Each revolution may take 5·10⁴ steps (the bicycle's take ~200 at 1e-10): a crank held by
  // friction chatters at rest and would otherwise use the integrator's whole budget.
  IntegratorLimits limits;
  limits.max_steps = 50000;
  SectionSpeed out;
  // Φ(v); NaN when the period is not completed.
  auto map = [&](double v, double& period) {
    ++out.passes;
    AdaptiveIntegrator integ(m, opt.tolerance, "rk8pd", limits);
    integ.reset(0.0, qs, v);
    // A period takes P/|v| at the starting speed; allow 20 times that before calling it a stall.
    bool done = false;
    try {
      done = integ.advance(20.0 * P / std::max(std::abs(v), 1e-3), qs + s * P);
    } catch (const models::NumericalError&) {
      done = false;  // over its budget: a stall
    }
    out.steps += integ.steps();
    period = integ.state().t;
    return done ? integ.state().qdot : NAN;
  };
  double p0 = NAN, p1 = NAN;
  double v0 = opt.qdot_guess, g0 = map(v0, p0) - v0;
  double v1 = std::isfinite(g0) ? v0 + g0 : v0 * 1.01, g1 = map(v1, p1) - v1;
  bool ok = false;
  while (out.passes < opt.max_passes && std::isfinite(g0) && std::isfinite(g1)) {
    if (std::abs(g1) < kFixedPointTolerance * std::abs(v1)) {
      ok = true;
      break;
    }
    const double v2 = v1 - g1 * (v1 - v0) / (g1 - g0);
    if (!(s * v2 > 0) || !std::isfinite(v2)) break;
    v0 = v1, g0 = g1, p0 = p1;
    v1 = v2;
    g1 = map(v1, p1) - v1;
  }
  if (!ok && !(std::isfinite(g1) && std::abs(g1) < kFixedPointStagnation * std::abs(v1)))
    throw models::NumericalError(fmt::format(
        "steady cycle (time stepping): no periodic cycle found in {} revolutions from q̇ = {:.6g} rad/s at q = {:.6g}° "
        "({})",
        out.passes, opt.qdot_guess, qs * 180 / M_PI,
        std::isfinite(g1) ? fmt::format("the speed still changes by {:.3g} of itself per cycle", std::abs(g1 / v1))
                          : "a revolution was not completed: the mechanism stalls or turns back"));
  out.qdot = v1;
  out.period_s = p1;
  return out;
}

struct CycleSample {
  double t, q, qdot, work;
  std::vector<char> gates;
};

// The cycle from (q_s, v) sampled at N + 1 equal steps of θ = s·(q − q_s) by stopping at each.
std::vector<CycleSample> sample_cycle(AdaptiveIntegrator& integ, const SteadyCycleOptions& opt, double P,
                                      double v, double t_max) {
  const double s = opt.qdot_guess > 0 ? 1.0 : -1.0, qs = opt.q_section;
  const int N = opt.samples;
  std::vector<CycleSample> smp;
  smp.reserve(N + 1);
  integ.reset(0.0, qs, v);
  smp.push_back({0.0, qs, v, 0.0, integ.state().gate_on});
  for (int i = 1; i <= N; ++i) {
    if (!integ.advance(t_max, qs + s * sample_theta(0.0, P, i, N)))
      throw models::NumericalError("steady cycle (time stepping): the cycle found does not complete a period");
    const auto& st = integ.state();
    smp.push_back({st.t, st.q, st.qdot, st.work, st.gate_on});
  }
  return smp;
}

// Speed extremes and peak constraint forces over the sampled cycle (cycle_extremes.hpp): a point
// between samples is reached by integrating from the sample before it, stopped there like an event.
void fill_extremes(const ReducedModel& m, const SteadyCycleOptions& opt, const std::vector<CycleSample>& smp,
                   AdaptiveIntegrator& integ, SteadyCycle& c) {
  const double P = m.table.period, qs = opt.q_section, v = smp.front().qdot, s = opt.qdot_guess > 0 ? 1.0 : -1.0;
  const int N = opt.samples;
  const double dth = P / N;
  ReducedWorkspace ws(m);
  std::vector<double> forces(m.force_names.size()), value, where;
  auto eval = [&](int, double theta, double* out) {
    int i = std::clamp(static_cast<int>(std::floor(theta / dth)), 0, N);
    while (i > 0 && sample_theta(0.0, P, i, N) > theta) --i;
    while (i < N && sample_theta(0.0, P, i + 1, N) <= theta) ++i;
    // At a sample, or so close after it that the sample (stopped just past its angle) is already
    // there: the sample itself.
    const CycleSample& at = smp[i];
    if (theta == sample_theta(0.0, P, i, N) || s * (at.q - (qs + s * theta)) >= 0) {
      ws.gate_on = at.gates;
      quantities_at(m, ws, at.q, at.qdot, forces, out);
      return;
    }
    integ.reset(at.t, at.q, at.qdot, at.work);
    if (!integ.advance(at.t + 20.0 * P / std::abs(v), qs + s * theta))
      throw models::NumericalError("steady cycle (time stepping): the cycle found does not complete a period");
    ws.gate_on = integ.state().gate_on;
    quantities_at(m, ws, integ.state().q, integ.state().qdot, forces, out);
  };
  find_extremes(std::vector<double>{0.0}, std::vector<double>{P}, N, P, quantity_count(m), eval, value, where);
  c.speed_max = value[0];
  c.speed_min = -value[1];
  for (size_t k = 0; k < forces.size(); ++k) {
    c.peak_force_N.push_back(value[2 + k]);
    const double q = qs + s * where[2 + k];
    c.peak_force_q.push_back(q - P * std::floor((q - m.table.q0) / P));
  }
}

// Work of the resistances per cycle, ∫ F_b dq = s ∫ (P_b / q̇) dθ, by Simpson's rule over the
// samples (trapezoids for an odd count): the integrator only carries the total work.
double brake_work_per_cycle(const ReducedModel& m, const std::vector<CycleSample>& smp, double s, double P) {
  const int N = static_cast<int>(smp.size()) - 1;
  const double dth = P / N;
  std::vector<double> fb(N + 1);
  for (int i = 0; i <= N; ++i) fb[i] = s * brake_power(m, smp[i].q, smp[i].qdot) / smp[i].qdot;
  double work = 0.0;
  if (N % 2 == 0) {
    for (int i = 0; i < N; i += 2) work += dth / 3 * (fb[i] + 4 * fb[i + 1] + fb[i + 2]);
  } else {
    for (int i = 0; i < N; ++i) work += 0.5 * dth * (fb[i] + fb[i + 1]);
  }
  return work;
}

}  // namespace

SteadyCycle calc_steady_cycle_time_stepping(const ReducedModel& m, const SteadyCycleOptions& opt) {
  check_steady_cycle_options(opt);
  if (!m.table.periodic)
    throw models::NumericalError("steady cycle: the table is not periodic (the independent coordinate does not turn "
                                 "a full period), so there is no cycle");
  const double P = m.table.period;
  const SectionSpeed section = find_section_speed(m, opt);
  const double v1 = section.qdot, s = opt.qdot_guess > 0 ? 1.0 : -1.0;
  SteadyCycle c;
  c.method = CycleMethod::TimeStepping;
  c.passes = section.passes + 1;  // and the sampled pass
  c.qdot_section = v1;
  c.period_s = section.period_s;
  IntegratorLimits limits;
  limits.max_steps = 1000000;
  AdaptiveIntegrator integ(m, opt.tolerance, "rk8pd", limits);
  const auto smp = sample_cycle(integ, opt, P, v1, 20.0 * P / std::abs(v1) + 10.0 * section.period_s);
  fill_extremes(m, opt, smp, integ, c);
  fill_work(c, P, smp.back().work, brake_work_per_cycle(m, smp, s, P));
  c.steps = section.steps + integ.steps();
  // As the first integral's test: the energy gained per cycle (the work of every
  // non-conservative load) is below 1e-6 of the work flowing through it — not a runaway.
  const double flow = std::abs(c.drive_work_J) + std::abs(c.dissipated_work_J);
  if (flow > 0 && !(std::abs(smp.back().work) <= 1e-6 * flow))
    throw models::NumericalError(fmt::format(
        "steady cycle (time stepping): no periodic cycle: the speed keeps changing (the mechanism gains {:.3g} J per "
        "cycle of {:.3g} J of drive work)",
        smp.back().work, c.drive_work_J));
  check_finite(c, "time stepping");
  return c;
}

struct CyclePasses::Impl {
  FirstIntegral fi;
  Impl(const ReducedModel& m, const SteadyCycleOptions& opt) : fi(m, opt) {}
};

CyclePasses::CyclePasses(const ReducedModel& m, const SteadyCycleOptions& opt) {
  check_steady_cycle_options(opt);
  if (!m.table.periodic)
    throw models::NumericalError("steady cycle: the table is not periodic (the independent coordinate does not turn "
                                 "a full period), so there is no cycle");
  impl_ = std::make_unique<Impl>(m, opt);
}

CyclePasses::~CyclePasses() = default;

CyclePasses::Pass CyclePasses::run(double u0) {
  Pass p;
  if (!(u0 > 0 && std::isfinite(u0))) return p;
  ++passes_;
  auto& fi = impl_->fi;
  // The workspace copied the joint torques' values when it was made; the caller may have
  // changed them since (the gates and the switching cache do not depend on values).
  for (size_t i = 0; i < fi.m.torques.size(); ++i) fi.ws.torque_value[i] = fi.m.torques[i].value;
  if (!fi.pass(u0)) return p;
  p.completed = true;
  p.u_end = fi.y_end[0];
  p.period_s = fi.y_end[1];
  p.work_nc_J = fi.y_end[2];
  p.work_brakes_J = fi.y_end[3];
  return p;
}

SteadyCycle find_steady_cycle(const ReducedModel& m, const SteadyCycleOptions& opt) {
  check_steady_cycle_options(opt);
  try {
    return calc_steady_cycle(m, opt);
  } catch (const models::NumericalError& first) {
    try {
      return calc_steady_cycle_time_stepping(m, opt);
    } catch (const models::NumericalError& second) {
      throw models::NumericalError(fmt::format("{}; {}", first.what(), second.what()));
    }
  }
}

}  // namespace rdyn::reduced
