// Refinements of the extraction's grid visit (reduced/sweep_refine.hpp).
#include "reduced/sweep_refine.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "models/scene.hpp"

namespace rdyn::reduced {

namespace {

struct RatioRootContext {
  KinetostaticSource* src;
  int joint;
};

double ratio_at(double q, void* p) {
  auto* c = static_cast<RatioRootContext*>(p);
  return c->src->ratio(q, c->joint);
}

// Combines one value of the four samples at q_s − δ, q_s − δ/2, q_s + δ/2, q_s + δ.
double richardson_limit(double m1, double m2, double p2, double p1) {
  return (4 * 0.5 * (m2 + p2) - 0.5 * (m1 + p1)) / 3;
}
bool limit_values(double& out, const double* v[4]) {
  out = richardson_limit(*v[0], *v[1], *v[2], *v[3]);
  return std::isfinite(out);
}
bool limit_values(std::vector<double>& out, const std::vector<double>* v[4]) {
  for (int k = 1; k < 4; ++k)
    if (v[k]->size() != v[0]->size()) return false;
  out.resize(v[0]->size());
  bool ok = true;
  for (size_t i = 0; i < out.size(); ++i) {
    out[i] = richardson_limit((*v[0])[i], (*v[1])[i], (*v[2])[i], (*v[3])[i]);
    ok &= std::isfinite(out[i]);
  }
  return ok;
}
bool limit_values(std::vector<std::vector<double>>& out, const std::vector<std::vector<double>>* v[4]) {
  for (int k = 1; k < 4; ++k)
    if (v[k]->size() != v[0]->size()) return false;
  out.resize(v[0]->size());
  bool ok = true;
  for (size_t i = 0; i < out.size(); ++i) {
    const std::vector<double>* row[4] = {&(*v[0])[i], &(*v[1])[i], &(*v[2])[i], &(*v[3])[i]};
    ok &= limit_values(out[i], row);
  }
  return ok;
}
// Every field of the four samples' limit into `g` (positions included: they are determined
// at q_s, and their limit is the same value). False when a side sample is itself singular or a
// value is not finite: the caller keeps the spline repair then.
template <class T, class Get>
bool limit_field(T& out, const GridSample* side[4], Get get) {
  const T* v[4] = {&get(*side[0]), &get(*side[1]), &get(*side[2]), &get(*side[3])};
  return limit_values(out, v);
}

}  // namespace

// The zero of joint j's velocity ratio inside one grid interval [a, b] (ra, rb of opposite
// signs), located on the full model: a tight bracket around the estimate, widened until the
// sign changes, then Brent's method (GSL). Called while the sweep stands at that interval, so
// every evaluation is a short continuation step.
double refine_root(KinetostaticSource& src, int j, double a, double ra, double b, double rb, double est) {
  if (ra == 0.0) return a;
  if (rb == 0.0) return b;
  std::unique_ptr<gsl_root_fsolver, decltype(&gsl_root_fsolver_free)> solver(
      gsl_root_fsolver_alloc(gsl_root_fsolver_brent), gsl_root_fsolver_free);
  RatioRootContext ctx{&src, j};
  gsl_function fn{ratio_at, &ctx};
  auto brent = [&](double lo, double hi) {
    gsl_root_fsolver_set(solver.get(), &fn, lo, hi);
    double root = 0.5 * (lo + hi);
    for (int it = 0; it < 100; ++it) {
      if (gsl_root_fsolver_iterate(solver.get()) != GSL_SUCCESS) break;
      root = gsl_root_fsolver_root(solver.get());
      if (gsl_root_test_interval(gsl_root_fsolver_x_lower(solver.get()), gsl_root_fsolver_x_upper(solver.get()),
                                 1e-13, 0.0) == GSL_SUCCESS)
        break;
    }
    return root;
  };
  est = std::min(b, std::max(a, est));
  for (double w = 1e-3 * (b - a); w < (b - a); w *= 6) {
    const double l = std::max(a, est - w), h = std::min(b, est + w);
    const double fl = l == a ? ra : src.ratio(l, j), fh = h == b ? rb : src.ratio(h, j);
    if (fl == 0.0) return l;
    if (fh == 0.0) return h;
    if ((fl > 0) != (fh > 0)) return brent(l, h);
  }
  return brent(a, b);
}

// The zero of joint j's velocity ratio inside one grid interval [a, b] (ra, rb of opposite
// signs, sa, sb the slopes dr/dq there) by Newton's method on the full model: started from the
// zero of the cubic Hermite interpolant of the two samples (error O(h⁴)), each step one
// evaluation of r and dr/dq; a step leaving the shrinking bracket bisects it. Converged when
// the step is ≤ 1e-13 (Brent's interval tolerance in refine_root) or when quadratic
// convergence, e_next ≈ K dx² with K ≈ |dx| / dx_prev², puts the next error below 1e-15.
// Empty after 8 evaluations without convergence (the caller falls back to refine_root).
std::optional<double> newton_root(KinetostaticSource& src, int j, double a, double ra, double sa, double b, double rb,
                                  double sb) {
  if (ra == 0.0) return a;
  if (rb == 0.0) return b;
  const double h = b - a;
  auto hermite = [&](double t) {  // the cubic Hermite interpolant at a + t h
    const double t2 = t * t, t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * ra + (t3 - 2 * t2 + t) * h * sa + (-2 * t3 + 3 * t2) * rb + (t3 - t2) * h * sb;
  };
  double lo = 0, hi = 1;  // bisection of the interpolant (its end values have opposite signs)
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    if ((hermite(mid) > 0) == (ra > 0)) lo = mid;
    else hi = mid;
  }
  double x = a + 0.5 * (lo + hi) * h, xa = a, xb = b, prev = NAN;
  for (int it = 0; it < 8; ++it) {
    const auto e = src.ratio_and_slope(x, j);
    if (!e) return std::nullopt;
    const auto [f, fp] = *e;
    if (f == 0.0) return x;
    if ((f > 0) == (ra > 0)) xa = x;
    else xb = x;
    const double dx = -f / fp;
    // At the root to rounding the step is below an ulp, x + dx == x == one end of the bracket:
    // converged, not a step out of the bracket (it used to bisect away from the root here).
    if (std::isfinite(dx) && std::abs(dx) <= 1e-13) return x + dx;
    if (!std::isfinite(dx) || !(x + dx > xa && x + dx < xb)) {
      x = 0.5 * (xa + xb), prev = NAN;
      continue;
    }
    if (std::abs(dx) <= 1e-13 || (std::isfinite(prev) && std::abs(dx) <= 1e-6 && std::abs(dx) / (prev * prev) * dx * dx <= 1e-15))
      return x + dx;
    prev = std::abs(dx);
    x += dx;
  }
  return std::nullopt;
}

// Zero of the quadratic through three samples (x0 < x1 < x2) inside [x1, x2], else the chord.
double quadratic_zero(double x0, double y0, double x1, double y1, double x2, double y2) {
  const double chord = x1 - y1 * (x2 - x1) / (y2 - y1);
  const double d01 = (y1 - y0) / (x1 - x0), d12 = (y2 - y1) / (x2 - x1), c = (d12 - d01) / (x2 - x0);
  const double b = d12 + c * (x2 - x1);  // slope at x2 of p(x) = y2 + b (x − x2) + c (x − x2)²
  if (std::abs(c) < 1e-300) return chord;
  const double disc = b * b - 4 * c * y2;
  if (disc < 0) return chord;
  for (double sgn : {1.0, -1.0}) {
    const double dx = (-b + sgn * std::sqrt(disc)) / (2 * c);
    const double x = x2 + dx;
    if (x >= x1 && x <= x2) return x;
  }
  return chord;
}

// Where a point force's points meet between two grid points a < b (the full model stops there:
// the line has no direction). L(q) has a minimum inside where dL/dq turns from negative (La) to
// positive (Lb). Near it the points' relative motion is straight to first order, d(q) = d* + w·δ
// with d* ⊥ w, δ = q − q*, so L = √(L*² + |w|²δ²) and dL/dq = |w|²δ/L: smooth through q* when
// L* > 0, a jump of 2|w| when the points meet. Hence across a bracket of width ε with jump J,
// L* ≤ |w|²ε/J (|dL/dq| ≤ |w|²|δ|/L*), and ≈ |w|²ε/J once J ≪ |w|. Bisection on the sign of
// dL/dq (the source's length rate at any q) narrows the bracket until one of: met, the bound below
// the full model's own limit limits::kMinPointForceLength_m (|w| estimated by the largest |dL/dq|
// seen, ≤ |w|); apart, J < |w|/10 with the estimate 10× above that limit. At most 200 halvings.
std::optional<double> find_point_force_meeting(KinetostaticSource& src, long f, double a, double La, double b,
                                               double Lb) {
  constexpr double kMin = models::limits::kMinPointForceLength_m;
  double w = std::max(std::abs(La), std::abs(Lb));
  for (int it = 0; it < 200; ++it) {
    const double eps = b - a, J = Lb - La;
    w = std::max({w, std::abs(La), std::abs(Lb)});
    if (!(J > 0) || !(w > 0)) return std::nullopt;
    const double bound = w * w * eps / J;
    if (bound < kMin) return 0.5 * (a + b);
    if (J < 0.1 * w && bound > 10 * kMin) return std::nullopt;
    const double m = 0.5 * (a + b);
    if (!(m > a && m < b)) return bound < 10 * kMin ? std::optional<double>(m) : std::nullopt;  // at rounding
    RatioPoint rp;
    try {
      rp = src.ratios(m);
    } catch (const models::NumericalError& e) {
      // The source refuses this line shorter than the limit there: they meet (other failures pass on).
      if (std::string(e.what()).find("point force") == std::string::npos) throw;
      return m;
    }
    if (static_cast<long>(rp.length_wrt_q.size()) <= f || !std::isfinite(rp.length_wrt_q[f])) return m;
    (rp.length_wrt_q[f] < 0 ? a : b) = m;
    (rp.length_wrt_q[f] < 0 ? La : Lb) = rp.length_wrt_q[f];
  }
  return std::nullopt;
}

bool is_simple_pole(double m1, double m2, double p2, double p1) {
  const double a1 = 0.5 * (p1 - m1), a2 = 0.5 * (p2 - m2);  // antisymmetric parts at δ, δ/2
  const double s1 = 0.5 * (p1 + m1), s2 = 0.5 * (p2 + m2);  // symmetric parts
  const double growth = std::abs(a2) / std::abs(a1);
  return std::isfinite(growth) && growth > 1.8 && growth < 2.2 && (a1 > 0) == (a2 > 0) &&
         std::abs(a2) > 100 * std::abs(s2 - s1);
}

namespace {

// Per constraint force, the residue a of a pole a/(q − q_s) in me1, me2 and Q_x from the four
// side samples at ±δ/2 and ±δ: a = ½[f(q_s + δ/2) − f(q_s − δ/2)]·δ/2 where is_simple_pole, else 0.
std::vector<std::array<double, 3>> calc_pole_residues(const GridSample s[4], double d) {
  const size_t nk = s[0].acceleration.constraint_forces.size();
  std::vector<std::array<double, 3>> out(nk, {0.0, 0.0, 0.0});
  auto residue = [&](auto get) {
    double v[4];
    for (int i = 0; i < 4; ++i) v[i] = get(s[i]);
    return is_simple_pole(v[0], v[1], v[2], v[3]) ? 0.5 * (v[2] - v[1]) * 0.5 * d : 0.0;
  };
  for (size_t k = 0; k < nk; ++k) {
    out[k][0] = residue([k](const GridSample& x) { return x.acceleration.constraint_forces.at(k); });
    out[k][1] = residue([k](const GridSample& x) { return x.velocity.constraint_forces.at(k); });
    if (s[0].conservative.forces.constraint_forces.size() == nk)
      out[k][2] = residue([k](const GridSample& x) { return x.conservative.forces.constraint_forces.at(k); });
  }
  return out;
}

}  // namespace

bool calc_singular_limit(KinetostaticSource& src, double q_s, double grid_step, bool conservative_loads,
                         GridSample& g, std::vector<std::array<double, 3>>* pole_residues) {
  const double d = std::min(kSingularLimitStep_rad, grid_step / 4);
  // Away from q_s and back across it: each move is short, so the predictor stays on the branch
  // the sweep came along (from q_s itself it follows the chord, see calc_kinetostatic_sample).
  GridSample s[4] = {src.sample(q_s - d, conservative_loads), src.sample(q_s - d / 2, conservative_loads),
                     src.sample(q_s + d / 2, conservative_loads), src.sample(q_s + d, conservative_loads)};
  const GridSample* side[4] = {&s[0], &s[1], &s[2], &s[3]};
  for (const auto& x : s)
    if (x.singular) return false;
  GridSample out = g;
  bool ok = true;
  ok &= limit_field(out.velocity.driving_force, side, [](const GridSample& x) -> const double& { return x.velocity.driving_force; });
  ok &= limit_field(out.velocity.constraint_forces, side, [](const GridSample& x) -> const std::vector<double>& { return x.velocity.constraint_forces; });
  ok &= limit_field(out.acceleration.driving_force, side, [](const GridSample& x) -> const double& { return x.acceleration.driving_force; });
  ok &= limit_field(out.acceleration.constraint_forces, side, [](const GridSample& x) -> const std::vector<double>& { return x.acceleration.constraint_forces; });
  ok &= limit_field(out.conservative.forces.driving_force, side, [](const GridSample& x) -> const double& { return x.conservative.forces.driving_force; });
  ok &= limit_field(out.conservative.forces.constraint_forces, side, [](const GridSample& x) -> const std::vector<double>& { return x.conservative.forces.constraint_forces; });
  ok &= limit_field(out.conservative.potential_energy, side, [](const GridSample& x) -> const double& { return x.conservative.potential_energy; });
  ok &= limit_field(out.ratios.wrt_q, side, [](const GridSample& x) -> const std::vector<double>& { return x.ratios.wrt_q; });
  ok &= limit_field(out.ratios.wrt_x, side, [](const GridSample& x) -> const std::vector<std::vector<double>>& { return x.ratios.wrt_x; });
  ok &= limit_field(out.ratios.wrt_q_slope, side, [](const GridSample& x) -> const std::vector<double>& { return x.ratios.wrt_q_slope; });
  ok &= limit_field(out.ratios.length_wrt_q, side, [](const GridSample& x) -> const std::vector<double>& { return x.ratios.length_wrt_q; });
  ok &= limit_field(out.ratios.length_wrt_x, side, [](const GridSample& x) -> const std::vector<std::vector<double>>& { return x.ratios.length_wrt_x; });
  if (!ok) return false;
  if (pole_residues) *pole_residues = calc_pole_residues(s, d);
  out.velocity.joint_rates = out.ratios.wrt_q;
  g = std::move(out);
  return true;
}

}  // namespace rdyn::reduced
