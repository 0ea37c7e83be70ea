#include "models/load_profile.hpp"

#include <algorithm>
#include <cmath>

namespace rdyn::models {

namespace {

constexpr double kTwoPi = 6.28318530717958647692;

// Periodic cubic spline, n rows, spacing h_i = θ_{i+1} − θ_i (h_{n−1} wraps to θ_0 + 2π):
//   h_{i−1} M_{i−1} + 2(h_{i−1} + h_i) M_i + h_i M_{i+1} = 6 [(τ_{i+1} − τ_i)/h_i − (τ_i − τ_{i−1})/h_{i−1}]
// (indices mod n; de Boor, A Practical Guide to Splines, ch. IV). The cyclic tridiagonal
// system is solved by the Sherman–Morrison correction of the Thomas algorithm
// (Press et al., Numerical Recipes 3rd ed., §2.7.2).
std::vector<double> periodic_second_derivatives(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  std::vector<double> h(n), sub(n), diag(n), sup(n), rhs(n);
  for (size_t i = 0; i < n; ++i) h[i] = (i + 1 < n ? x[i + 1] : x[0] + kTwoPi) - x[i];
  for (size_t i = 0; i < n; ++i) {
    const size_t im = (i + n - 1) % n, ip = (i + 1) % n;
    sub[i] = h[im];
    diag[i] = 2 * (h[im] + h[i]);
    sup[i] = h[i];
    rhs[i] = 6 * ((y[ip] - y[i]) / h[i] - (y[i] - y[im]) / h[im]);
  }
  // A = T + u vᵀ with corner entries alpha = A[n−1][0] = sup[n−1], beta = A[0][n−1] = sub[0].
  const double alpha = sup[n - 1], beta = sub[0], gamma = -diag[0];
  std::vector<double> d = diag;
  d[0] -= gamma;
  d[n - 1] -= alpha * beta / gamma;
  auto thomas = [&](std::vector<double> r) {
    std::vector<double> c(n), out(n);
    double den = d[0];
    out[0] = r[0] / den;
    for (size_t i = 1; i < n; ++i) {
      c[i] = sup[i - 1] / den;
      den = d[i] - sub[i] * c[i];
      out[i] = (r[i] - sub[i] * out[i - 1]) / den;
    }
    for (size_t i = n - 1; i-- > 0;) out[i] -= c[i + 1] * out[i + 1];
    return out;
  };
  std::vector<double> u(n, 0.0);
  u[0] = gamma;
  u[n - 1] = alpha;
  const auto xs = thomas(rhs), z = thomas(u);
  const double fact = (xs[0] + beta * xs[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
  std::vector<double> m(n);
  for (size_t i = 0; i < n; ++i) m[i] = xs[i] - fact * z[i];
  return m;
}

}  // namespace

LoadProfile make_table_profile(std::string of, std::vector<double> theta_rad, std::vector<double> value) {
  LoadProfile p;
  p.of = std::move(of);
  p.table_d2 = periodic_second_derivatives(theta_rad, value);
  p.table_theta_rad = std::move(theta_rad);
  p.table_value = std::move(value);
  return p;
}

double calc_profile(const LoadProfile& p, double theta) {
  if (!p.is_table()) {
    double tau = p.a0;
    const size_t nh = std::max(p.a.size(), p.b.size());
    for (size_t k = 1; k <= nh; ++k) {
      const double ak = k <= p.a.size() ? p.a[k - 1] : 0.0, bk = k <= p.b.size() ? p.b[k - 1] : 0.0;
      tau += ak * std::cos(k * theta) + bk * std::sin(k * theta);
    }
    return tau;
  }
  const auto& x = p.table_theta_rad;
  const auto& y = p.table_value;
  const auto& M = p.table_d2;
  const size_t n = x.size();
  // Wrap into [θ_0, θ_0 + 2π) and find the interval [x_i, x_{i+1}] (the last one wraps).
  const double t = theta - kTwoPi * std::floor((theta - x[0]) / kTwoPi);
  const size_t i = std::max<std::ptrdiff_t>(0, std::upper_bound(x.begin(), x.end(), t) - x.begin() - 1);
  const size_t ip = (i + 1) % n;
  const double x1 = i + 1 < n ? x[i + 1] : x[0] + kTwoPi, h = x1 - x[i];
  const double A = (x1 - t) / h, B = 1.0 - A;
  // Cubic spline between knots (Numerical Recipes 3rd ed., eq. 3.3.3).
  return A * y[i] + B * y[ip] + ((A * A * A - A) * M[i] + (B * B * B - B) * M[ip]) * h * h / 6.0;
}

double calc_profile_bound(const LoadProfile& p) {
  if (!p.is_table()) {
    double s = std::abs(p.a0);
    for (double v : p.a) s += std::abs(v);
    for (double v : p.b) s += std::abs(v);
    return s;
  }
  // Between knots the spline departs from its chord by at most h²·max|M|/6 (each cubic term
  // is h²/6 · |A³ − A| · |M| with |A³ − A| ≤ 0.385), so the bound is max|τ_i| + h²·max|M|/6.
  double ymax = 0.0, mmax = 0.0, hmax = 0.0;
  const size_t n = p.table_theta_rad.size();
  for (size_t i = 0; i < n; ++i) {
    ymax = std::max(ymax, std::abs(p.table_value[i]));
    mmax = std::max(mmax, std::abs(p.table_d2[i]));
    const double x1 = i + 1 < n ? p.table_theta_rad[i + 1] : p.table_theta_rad[0] + kTwoPi;
    hmax = std::max(hmax, x1 - p.table_theta_rad[i]);
  }
  return ymax + hmax * hmax * mmax / 6.0;
}

}  // namespace rdyn::models
