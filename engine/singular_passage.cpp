#include "engine/singular_passage.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "engine/branch_rates.hpp"
#include "engine/full_model_impl.hpp"
#include "engine/kinetostatic.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

// The unit of the independent coordinate's moves: 1 rad, or the mechanism's size [m].
double coordinate_unit(const FullModel& model) {
  const auto& m = model.impl();
  return m.scene.joints[m.independent].type == models::JointType::Revolute ? 1.0 : calc_length_scale(m.scene);
}

double conditioning_at(const FullModel& model, BranchGuard& g, double q) {  // along the branch
  follow_branch(model, g.ws, q, g.max_move, g.max_correction);
  return calc_loop_conditioning(model, g.ws);
}

// Golden-section search for the conditioning's minimum in [a, b] (unimodal there: it passes
// through rank loss linearly, |q − q*|). 60 reductions bring a 0.04 bracket to ~1e-14.
std::pair<double, double> refine_minimum(const FullModel& model, BranchGuard& g, double a, double b) {
  constexpr double r = 0.6180339887498949;
  double c = b - r * (b - a), d = a + r * (b - a);
  double fc = conditioning_at(model, g, c), fd = conditioning_at(model, g, d);
  for (int it = 0; it < 60 && std::abs(b - a) > 1e-12 * std::max(1.0, std::abs(a)); ++it) {
    if (fc < fd) {
      b = d, d = c, fd = fc;
      c = b - r * (b - a);
      fc = conditioning_at(model, g, c);
    } else {
      a = c, c = d, fc = fd;
      d = a + r * (b - a);
      fd = conditioning_at(model, g, d);
    }
  }
  return fc < fd ? std::make_pair(c, fc) : std::make_pair(d, fd);
}

// The smallest of 2.5e-4, 5e-4, 1e-3, … units (up to `cap`) at which the conditioning is at least
// `level` on both sides of q_s: a window's half-width, the limit radius.
double radius_above(const FullModel& model, BranchGuard& g, double q_s, double level, double cap) {
  double w = 2.5e-4 * coordinate_unit(model);
  for (; w < cap; w *= 2)
    if (conditioning_at(model, g, q_s - w) >= level && conditioning_at(model, g, q_s + w) >= level) return w;
  return cap;
}

// Signed distance from the configuration of rank loss (modulo a turn when periodic).
double offset(const SingularPoint& p, bool periodic, double q) {
  return periodic ? std::remainder(q - p.q, 2 * Pi) : q - p.q;
}

}  // namespace

std::vector<SingularPoint> calc_singular_points(const FullModel& model, const IndependentDomain& domain) {
  const auto& m = model.impl();
  if (m.constraints.empty()) return {};  // no loop or unfolded gear: the Jacobian has no rows
  if (!domain.periodic && !(std::isfinite(domain.min) && std::isfinite(domain.max))) return {};
  const double unit = coordinate_unit(model), move = kScanMove * unit;
  BranchGuard g(model);
  calc_kinetostatic(model, g.ws, m.scene.initial.q, 0.0, 0.0, Loads::Off);
  // The walk: one turn from the initial q, or the domain from edge to edge.
  const double from = domain.periodic ? m.scene.initial.q : domain.min;
  const double to = domain.periodic ? m.scene.initial.q + 2 * Pi : domain.max;
  const long n = std::max(2L, static_cast<long>(std::ceil((to - from) / move)));
  std::vector<double> x(n + 1), k(n + 1);
  for (long i = 0; i <= n; ++i) {
    x[i] = from + (to - from) * static_cast<double>(i) / static_cast<double>(n);
    k[i] = conditioning_at(model, g, x[i]);
  }
  std::vector<SingularPoint> out;
  // Local minima (periodic: the walk's two ends are one point). Within a range its end points
  // count too, refined over their one interval: a rank loss a hair inside a declared edge has
  // its smallest sampled conditioning at the edge itself (a 3-loop chain's flat 180° inside
  // [170°, 180.1°] was missed and Simbody crossed it alone, 1.6e-3 rad off with exit 0).
  for (long i = 0; i <= (domain.periodic ? n - 1 : n); ++i) {
    double a = 0.0, b = 0.0;
    if (domain.periodic) {
      const long lo = i > 0 ? i - 1 : n - 1;
      if (!(k[i] < kScanCandidate && k[i] <= k[lo] && k[i] <= k[i + 1])) continue;
      a = i > 0 ? x[lo] : x[0] - (x[n] - x[n - 1]), b = x[i + 1];
    } else {
      const bool low = i == 0 || k[i] <= k[i - 1], high = i == n || k[i] <= k[i + 1];
      if (!(k[i] < kScanCandidate && low && high)) continue;
      a = x[std::max(0L, i - 1)], b = x[std::min(n, i + 1)];
    }
    const auto [q_s, k_s] = refine_minimum(model, g, a, b);
    if (!(k_s < kSingularConditioning)) continue;  // a narrow place, not rank loss (no window)
    if (!out.empty() && std::abs(offset(out.back(), domain.periodic, q_s)) < 1e-9 * unit) continue;
    const double half = radius_above(model, g, q_s, kPassageConditioning, kMaxPassageHalfWidth * unit);
    out.push_back({q_s, half, radius_above(model, g, q_s, kLimitConditioning, half / 4), k_s});
  }
  return out;
}

int find_window(const std::vector<SingularPoint>& points, bool periodic, double a, double b) {
  for (size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i];
    const double a_off = offset(p, periodic, a), b_off = a_off + (b - a);
    const double lo = std::min(a_off, b_off), hi = std::max(a_off, b_off);
    for (int turn = periodic ? -1 : 0; turn <= (periodic ? 1 : 0); ++turn) {
      const double c = turn * 2 * Pi;
      if (hi >= c - p.half_width && lo <= c + p.half_width) return static_cast<int>(i);
    }
  }
  return -1;
}

bool outside_windows(const std::vector<SingularPoint>& points, bool periodic, double q) {
  for (const auto& p : points)
    if (!(std::abs(offset(p, periodic, q)) > p.half_width)) return false;
  return true;
}

namespace {

// Whether q moves toward the nearest window's edge.
bool approaching(const std::vector<SingularPoint>& points, bool periodic, double q, double qdot) {
  double nearest = INFINITY, side = 0.0;
  for (const auto& p : points) {
    const double o = offset(p, periodic, q);
    if (std::abs(o) - p.half_width < nearest) nearest = std::abs(o) - p.half_width, side = o;
  }
  return side * qdot < 0;
}

}  // namespace

namespace {

// The branch workspace at (q, q̇): positions by continuation, velocities u = r q̇ from the branch
// rates (linear solves with the loop Jacobian, polished near rank loss as the kinetostatic
// sample is; no velocity projection, which stalls there). Leaves the independent law at
// (q, q̇, 0) and the loads off; r, b and the conditioning in `rates`.
double set_branch_velocity(const FullModel& model, BranchGuard& g, double q, double qdot, BranchRates& rates) {
  const auto& m = model.impl();
  follow_branch(model, g.ws, q, g.max_move, g.max_correction);
  State& s = g.ws.impl().state;
  m.set_law(s, 0, poly_law(q, 1.0, 0.0));
  m.set_load_mode(s, kLoadsOff);
  calc_branch_rates(m, s, rates);
  double k = rates.conditioning;
  if (k >= kSingularConditioning && k < kPolishConditioning) {
    polish_projection(m, s);
    calc_branch_rates(m, s, rates);
    k = rates.conditioning;
  }
  m.set_law(s, 0, poly_law(q, qdot, 0.0));
  s.updU() = rates.r * qdot;
  return k;
}

// Free motion by virtual power along r (G r = 0, zero on the constraint actuators): with u̇ =
// r q̈ + b q̇², rᵀ(M u̇ + c) = rᵀ f gives m1 q̈ + m2 q̇² = F*, m1 = rᵀ M r, m2 = rᵀ(M b + c(r)) (the
// kinetostatic sample's terms, docs/theory.md §4) and F* = rᵀ f(q, r q̇) with every load
// applied (gates from the instantaneous rates, as the kinetostatic calls with Loads::All).
FreeMotion direct_free_motion(const FullModel& model, BranchGuard& g, double q, double qdot) {
  const auto& m = model.impl();
  BranchRates rates;
  State& s = g.ws.impl().state;
  // m1 and m2 at u = r (q̇ = 1), then the loads at u = r q̇.
  set_branch_velocity(model, g, q, 1.0, rates);
  m.system.realize(s, Stage::Velocity);
  Vector Mr, inertial;
  m.matter.multiplyByM(s, rates.r, Mr);
  m.matter.calcResidualForceIgnoringConstraints(s, Vector(), Vector_<SpatialVec>(), rates.b, inertial);
  const double m1 = ~rates.r * Mr, m2 = ~rates.r * inertial;
  m.set_law(s, 0, poly_law(q, qdot, 0.0));
  s.updU() = rates.r * qdot;
  m.set_load_mode(s, kLoadsInstant);
  m.system.realize(s, Stage::Dynamics);
  Vector f;
  m.matter.multiplyBySystemJacobianTranspose(s, m.system.getRigidBodyForces(s, Stage::Dynamics), f);
  f += m.system.getMobilityForces(s, Stage::Dynamics);
  const double F = ~rates.r * f;
  if (!(m1 > 0) || !std::isfinite(m2) || !std::isfinite(F))
    throw models::NumericalError(fmt::format(
        "full model: m1 = {:.6g}, m2 = {:.6g}, F* = {:.6g} at {} (the partitioned formulation of a singular passage "
        "needs m1 > 0 and finite terms)",
        m1, m2, F,
        format_coordinate(q, m.scene.joints[m.independent].type == models::JointType::Revolute)));
  return {(F - m2 * qdot * qdot) / m1, non_conservative_power(m, s)};
}

}  // namespace

LimitStencil limit_stencil_at(const std::vector<SingularPoint>& points, bool periodic, double q) {
  for (const auto& p : points) {
    const double o = offset(p, periodic, q), r = p.limit_radius;
    if (!(std::abs(o) < r)) continue;
    // Nodes q* ± r, ± 2r, ± 3r (in q's labelling of turns); Lagrange weights at q.
    LimitStencil st;
    for (const double c : {-3.0, -2.0, -1.0, 1.0, 2.0, 3.0}) st.x.push_back(q - o + c * r);
    for (size_t i = 0; i < st.x.size(); ++i) {
      double w = 1.0;
      for (size_t j = 0; j < st.x.size(); ++j)
        if (j != i) w *= (q - st.x[j]) / (st.x[i] - st.x[j]);
      st.w.push_back(w);
    }
    return st;
  }
  return {};
}

FreeMotion calc_free_motion(const FullModel& model, BranchGuard& g, double q, double qdot, const LimitStencil& st) {
  if (st.x.empty()) return direct_free_motion(model, g, q, qdot);
  FreeMotion out;
  for (size_t i = 0; i < st.x.size(); ++i) {
    const auto f = direct_free_motion(model, g, st.x[i], qdot);
    out.qddot += st.w[i] * f.qddot;
    out.power += st.w[i] * f.power;
  }
  return out;
}

double set_passage_state(const FullModel& model, BranchGuard& g, double q, double qdot, double qddot) {
  const auto& m = model.impl();
  BranchRates rates;
  const double k = set_branch_velocity(model, g, q, qdot, rates);
  State& s = g.ws.impl().state;
  m.set_law(s, 0, poly_law(q, qdot, qddot));
  m.set_load_mode(s, kLoadsInstant);
  m.system.realize(s, Stage::Acceleration);
  return k;
}

namespace {

// Dormand–Prince 5(4) (Hairer, Nørsett & Wanner, Solving ODEs I, Table 5.2), first-same-as-last.
constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
constexpr double a21 = 1.0 / 5;
constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729;
constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                 a65 = -5103.0 / 18656;
constexpr double b1 = 35.0 / 384, b3 = 500.0 / 1113, b4 = 125.0 / 192, b5 = -2187.0 / 6784, b6 = 11.0 / 84;
// b − b̂ (the error estimate's weights).
constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                 e6 = 22.0 / 525, e7 = -1.0 / 40;

struct Y {
  double q, v, w;  // q, q̇, work
  Y operator+(const Y& o) const { return {q + o.q, v + o.v, w + o.w}; }
  Y operator*(double h) const { return {q * h, v * h, w * h}; }
};

}  // namespace

PassagePoint integrate_passage(const FullModel& model, BranchGuard& g, const std::vector<SingularPoint>& points,
                               bool periodic, const PassagePoint& start, const PassageOptions& opt,
                               const std::function<double()>& next_output,
                               const std::function<void(const PassagePoint&)>& on_output, long& steps) {
  const auto clock_start = std::chrono::steady_clock::now();
  auto f = [&](const Y& y) {
    const auto st = limit_stencil_at(points, periodic, y.q);
    const auto fm = calc_free_motion(model, g, y.q, y.v, st);
    return Y{y.v, fm.qddot, fm.power};
  };
  const double unit = coordinate_unit(model);
  double t = start.t;
  Y y{start.q, start.qdot, start.work};
  Y k1 = f(y);
  // First step: a hundredth of the time to cross a window at the start speed, at most 1 ms.
  double h = std::min(1e-3, 1e-2 * unit / std::max(std::abs(y.v), 1e-3));
  steps = 0;
  bool entered = false;  // the motion has been inside a window
  for (;;) {
    const double t_out = next_output();
    const bool outside = outside_windows(points, periodic, y.q);
    entered |= !outside;
    if (t >= opt.t_end - 1e-14 * std::max(1.0, opt.t_end)) break;
    // Done when out again, or when it turned back before reaching the window.
    if (outside && steps > 0 && (entered || !approaching(points, periodic, y.q, y.v))) break;
    if (steps >= opt.max_steps)
      throw models::NumericalError(fmt::format("full model's singular passage stopped at t = {:.6g} s: step budget of "
                                               "{} steps exhausted",
                                               t, opt.max_steps));
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count() > opt.max_wall_s)
      throw models::NumericalError(fmt::format("full model's singular passage stopped at t = {:.6g} s: wall-time "
                                               "budget of {:g} s exhausted",
                                               t, opt.max_wall_s));
    const bool landing = t + h >= t_out - 1e-14 * std::max(1.0, t_out);
    const double hs = landing ? t_out - t : h;
    const Y k2 = f(y + k1 * (hs * a21));
    const Y k3 = f(y + (k1 * a31 + k2 * a32) * hs);
    const Y k4 = f(y + (k1 * a41 + k2 * a42 + k3 * a43) * hs);
    const Y k5 = f(y + (k1 * a51 + k2 * a52 + k3 * a53 + k4 * a54) * hs);
    const Y k6 = f(y + (k1 * a61 + k2 * a62 + k3 * a63 + k4 * a64 + k5 * a65) * hs);
    const Y y_new = y + (k1 * b1 + k3 * b3 + k4 * b4 + k5 * b5 + k6 * b6) * hs;
    const Y k7 = f(y_new);
    const Y err = (k1 * e1 + k3 * e3 + k4 * e4 + k5 * e5 + k6 * e6 + k7 * e7) * hs;
    // Error relative to max(|y|, 1 unit): the accuracy Simbody's integrators are asked for. The
    // work integral follows q and q̇ (W' = P(q, q̇)) and is not controlled on its own.
    auto rel = [&](double e, double a, double b) {
      return std::abs(e) / (opt.tolerance * std::max({std::abs(a), std::abs(b), unit}));
    };
    const double en = std::max(rel(err.q, y.q, y_new.q), rel(err.v, y.v, y_new.v));
    if (!std::isfinite(en) || !std::isfinite(y_new.q) || !std::isfinite(y_new.v))
      throw models::NumericalError(fmt::format("full model's singular passage produced a non-finite value at t = {:.6g} s", t));
    const double grow = en > 0 ? 0.9 * std::pow(en, -0.2) : 5.0;
    if (en <= 1.0) {
      t = landing ? t_out : t + hs;
      y = y_new;
      k1 = k7;
      ++steps;
      if (landing) on_output({t, y.q, y.v, y.w});
      if (!landing || hs >= h) h = hs * std::clamp(grow, 0.2, 5.0);
    } else {
      h = hs * std::clamp(grow, 0.1, 0.9);
      if (!(h > 1e-14 * std::max(1.0, std::abs(t))))
        throw models::NumericalError(fmt::format("full model's singular passage at t = {:.6g} s: the step shrank to "
                                                 "{:.3g} s",
                                                 t, h));
    }
  }
  return {t, y.q, y.v, y.w};
}

}  // namespace rdyn::engine
