#include "validate/analysis/fourier_minimum.hpp"

#include <algorithm>
#include <cmath>

namespace rdyn::validate {

double calc_fourier_minimum(double a0, const std::vector<double>& a, const std::vector<double>& b) {
  const size_t H = std::max(a.size(), b.size());
  auto coef = [&](const std::vector<double>& c, size_t k) { return k < c.size() ? c[k] : 0.0; };
  // τ, τ′, τ″ at θ.
  auto eval = [&](double th, double& d1, double& d2) {
    double v = a0;
    d1 = d2 = 0.0;
    for (size_t k = 0; k < H; ++k) {
      const double n = static_cast<double>(k + 1), c = std::cos(n * th), s = std::sin(n * th);
      const double ak = coef(a, k), bk = coef(b, k);
      v += ak * c + bk * s;
      d1 += n * (bk * c - ak * s);
      d2 -= n * n * (ak * c + bk * s);
    }
    return v;
  };
  // A grid of N = 16(H + 1) angles (≥ 8 points per period of the highest harmonic): each local
  // minimum of the samples brackets one of τ's (τ′ has at most 2H zeros), refined by Newton on
  // τ′ within ± one spacing (quadratic convergence; 30 steps bound it).
  const size_t N = 16 * (H + 1);
  const double h = 2 * M_PI / static_cast<double>(N);
  std::vector<double> v(N);
  double d1 = 0.0, d2 = 0.0, lowest = HUGE_VAL;
  for (size_t i = 0; i < N; ++i) v[i] = eval(h * static_cast<double>(i), d1, d2), lowest = std::min(lowest, v[i]);
  for (size_t i = 0; i < N && H > 0; ++i) {
    if (!(v[i] <= v[(i + N - 1) % N] && v[i] <= v[(i + 1) % N])) continue;
    const double th0 = h * static_cast<double>(i);
    double th = th0;
    for (int it = 0; it < 30; ++it) {
      eval(th, d1, d2);
      if (!(d2 > 0)) break;  // not convex here: the samples already hold the minimum's value
      const double step = d1 / d2;
      th -= step;
      if (std::abs(th - th0) > h) break;  // left its cell: another cell's minimum
      lowest = std::min(lowest, eval(th, d1, d2));
      if (std::abs(step) < 1e-14) break;
    }
  }
  return lowest;
}

}  // namespace rdyn::validate
