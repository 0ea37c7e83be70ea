#include "validate/analysis/operating_point.hpp"

#include <algorithm>
#include <array>
#include <utility>

#include "reduced/steady_cycle.hpp"

namespace rdyn::validate {

namespace {

using Vec = std::array<double, 3>;
using Mat = std::array<Vec, 3>;

double norm_inf(const Vec& r, int n) {
  double v = 0.0;
  for (int i = 0; i < n; ++i) v = std::max(v, std::abs(r[i]));
  return v;
}

// J x = b by Gaussian elimination with partial pivoting (n ≤ 3). False when J is singular to
// rounding or a value is not finite.
bool solve(Mat J, Vec b, int n, Vec& x) {
  double scale = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) scale = std::max(scale, std::abs(J[i][j]));
  if (!(scale > 0 && std::isfinite(scale))) return false;
  for (int c = 0; c < n; ++c) {
    int p = c;
    for (int i = c + 1; i < n; ++i)
      if (std::abs(J[i][c]) > std::abs(J[p][c])) p = i;
    if (!(std::abs(J[p][c]) > 1e-13 * scale)) return false;
    std::swap(J[p], J[c]);
    std::swap(b[p], b[c]);
    for (int i = c + 1; i < n; ++i) {
      const double f = J[i][c] / J[c][c];
      for (int j = c; j < n; ++j) J[i][j] -= f * J[c][j];
      b[i] -= f * b[c];
    }
  }
  for (int i = n - 1; i >= 0; --i) {
    double s = b[i];
    for (int j = i + 1; j < n; ++j) s -= J[i][j] * x[j];
    x[i] = s / J[i][i];
    if (!std::isfinite(x[i])) return false;
  }
  return true;
}

// Accepted residuals (see the header): periodicity as the fixed-point search's 1e-12 of u
// (reduced/steady_cycle.cpp), the cadence ten times looser (it follows u through the period's
// quadrature), the power within calibrate's 1e-8 with a margin.
constexpr double kTolerance[3] = {1e-12, 1e-11, 1e-10};
// Forward-difference step in the logarithms: the residuals are smooth (passes replay one step
// grid) and carry ~1e-14 of rounding, so the differences are good to ~1e-7.
constexpr double kDifference = 1e-7;
// Largest change of a logarithm in one step (a factor e): the first guesses are within tens of
// per cent (the load from the energy balance at constant speed, the speed from the cadence);
// a longer step is a sign of a poor Jacobian, not of a far root.
constexpr double kMaxStep = 1.0;

}  // namespace

std::optional<OperatingPoint> solve_operating_point(const reduced::ReducedModel& m, const OperatingPointTargets& t,
                                                    double load_guess, double coefficient_guess,
                                                    const std::function<void(double, double)>& apply, int& passes) {
  const bool power = std::isfinite(t.power_w);
  const int n = power ? 3 : 2;
  if (!(t.cadence_hz > 0 && std::isfinite(t.cadence_hz) && load_guess > 0 && std::isfinite(load_guess) &&
        t.qdot_guess != 0 && std::isfinite(t.qdot_guess) && (!power || (t.power_w > 0 && coefficient_guess > 0 &&
                                                                         std::isfinite(coefficient_guess)))))
    return std::nullopt;
  reduced::SteadyCycleOptions o;
  o.q_section = t.q_section;
  o.qdot_guess = t.qdot_guess;
  o.tolerance = t.tolerance;
  reduced::CyclePasses cp(m, o);  // throws on options out of range or a table that is not periodic
  struct Count {  // passes reach the caller's count on every return
    const reduced::CyclePasses& cp;
    int& passes;
    ~Count() { passes += cp.passes(); }
  } count{cp, passes};

  auto values = [&](const Vec& x) { apply(std::exp(x[1]), power ? std::exp(x[2]) : NAN); };
  auto residual = [&](const Vec& x, Vec& r) {
    values(x);
    const auto p = cp.run(std::exp(x[0]));
    if (!p.completed || !(p.u_end > 0) || !(p.period_s > 0)) return false;
    r[0] = std::log(p.u_end) - x[0];
    r[1] = std::log(t.cadence_hz * p.period_s);
    r[2] = 0.0;
    if (power) {
      const double dissipated = -p.work_brakes_J / p.period_s;
      if (!(dissipated > 0)) return false;
      r[2] = std::log(dissipated / t.power_w);
    }
    return std::isfinite(r[0]) && std::isfinite(r[1]) && std::isfinite(r[2]);
  };
  auto converged = [&](const Vec& r) {
    for (int i = 0; i < n; ++i)
      if (!(std::abs(r[i]) <= kTolerance[i])) return false;
    return true;
  };
  Mat J{};
  auto difference_jacobian = [&](const Vec& x, const Vec& r) {
    for (int k = 0; k < n; ++k) {
      Vec xk = x, rk{};
      xk[k] += kDifference;
      if (!residual(xk, rk)) return false;
      for (int i = 0; i < n; ++i) J[i][k] = (rk[i] - r[i]) / kDifference;
    }
    return true;
  };

  Vec x{std::log(0.5 * t.qdot_guess * t.qdot_guess), std::log(load_guess), power ? std::log(coefficient_guess) : 0.0};
  Vec r{};
  // A first pass that stalls started below the cycle (solutions of the first-order equation do
  // not cross, so a faster start stays faster all the way round): four times the energy, a few
  // times, as the fixed-point search does.
  bool started = residual(x, r);
  for (int k = 0; k < 4 && !started && cp.passes() < t.max_passes; ++k) x[0] += std::log(4.0), started = residual(x, r);
  if (!started || !difference_jacobian(x, r)) return std::nullopt;
  auto result = [&] {
    values(x);
    return OperatingPoint{std::exp(x[1]), power ? std::exp(x[2]) : NAN,
                          (t.qdot_guess > 0 ? 1.0 : -1.0) * std::sqrt(2 * std::exp(x[0]))};
  };
  while (cp.passes() < t.max_passes) {
    if (converged(r)) return std::optional<OperatingPoint>(result());
    Vec minus_r{}, dx{};
    for (int i = 0; i < n; ++i) minus_r[i] = -r[i];
    if (!solve(J, minus_r, n, dx)) return std::nullopt;
    const double longest = norm_inf(dx, n);
    if (longest > kMaxStep)
      for (int i = 0; i < n; ++i) dx[i] *= kMaxStep / longest;
    // Step halving: the full step unless it stalls a pass or does not reduce the residual.
    Vec xn{}, rn{};
    bool accepted = false;
    for (double lambda = 1.0; lambda >= 1.0 / 16 && cp.passes() < t.max_passes; lambda *= 0.5) {
      for (int i = 0; i < n; ++i) xn[i] = x[i] + lambda * dx[i];
      if (residual(xn, rn) && norm_inf(rn, n) < norm_inf(r, n)) {
        accepted = true;
        break;
      }
    }
    if (!accepted) return std::nullopt;
    const bool slow = norm_inf(rn, n) > 0.1 * norm_inf(r, n);
    // Broyden's update: J + ((Δr − J s) sᵀ) / (sᵀ s), s = Δx; a fresh difference Jacobian where
    // the residual fell by less than ten times (the update lags).
    Vec s{}, y{};
    double ss = 0.0;
    for (int i = 0; i < n; ++i) s[i] = xn[i] - x[i], y[i] = rn[i] - r[i], ss += s[i] * s[i];
    x = xn, r = rn;
    if (slow && !converged(r) && cp.passes() + n < t.max_passes) {
      if (!difference_jacobian(x, r)) return std::nullopt;
    } else if (ss > 0) {
      for (int i = 0; i < n; ++i) {
        double js = 0.0;
        for (int j = 0; j < n; ++j) js += J[i][j] * s[j];
        for (int j = 0; j < n; ++j) J[i][j] += (y[i] - js) * s[j] / ss;
      }
    }
  }
  if (converged(r)) return std::optional<OperatingPoint>(result());  // on the last pass allowed
  return std::nullopt;
}

}  // namespace rdyn::validate
