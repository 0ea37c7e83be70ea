#include "reduced/table_resolution.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

namespace rdyn::reduced {

double calc_half_grid_miss(const std::vector<double>& y) {
  const size_t n = y.size();
  if (n < 8 || n % 2 != 0) return NAN;
  const size_t m = n / 2;  // the half table: y[0], y[2], ...
  constexpr double kTwoPi = 6.283185307179586476925286766559;
  // Its discrete Fourier coefficients c_k, k = 0 … m/2 (real data: the others are conjugates).
  std::vector<std::complex<double>> c(m / 2 + 1);
  for (size_t k = 0; k < c.size(); ++k) {
    std::complex<double> s = 0.0;
    for (size_t j = 0; j < m; ++j) s += y[2 * j] * std::polar(1.0, -kTwoPi * static_cast<double>(k * j % m) / m);
    c[k] = s / static_cast<double>(m);
  }
  double peak = 0.0, miss = 0.0;
  for (double v : y) peak = std::max(peak, std::abs(v));
  if (peak == 0.0) return 0.0;
  for (size_t j = 0; j < m; ++j) {  // the odd sample 2j + 1, half a coarse step after y[2j]
    const double th = kTwoPi * (static_cast<double>(j) + 0.5) / static_cast<double>(m);
    double v = c[0].real();
    for (size_t k = 1; k < c.size(); ++k) {
      // The Nyquist term of an even m counts once (its interpolant is c·cos((m/2)θ)).
      const double w = (m % 2 == 0 && k == m / 2) ? 1.0 : 2.0;
      v += w * (c[k] * std::polar(1.0, static_cast<double>(k) * th)).real();
    }
    miss = std::max(miss, std::abs(v - y[2 * j + 1]));
  }
  return miss / peak;
}

}  // namespace rdyn::reduced
