// The exact minimum of a trigonometric polynomial (validate/analysis/fourier_minimum.cpp).
#include "validate/analysis/fourier_minimum.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rdyn::validate {
namespace {

// The minimum of a trigonometric polynomial: closed forms where it falls between any fixed
// sampling (72 angles), and a brute-force dense grid as the second route.
TEST(FourierMinimum, FourierMinimumIsTheSeriesOwnNotASample) {
  // 1 + c·cos(Hθ − φ): minimum 1 − c at θ = (φ + π)/H, placed half-way between 5° samples.
  for (int H : {1, 3, 7, 12}) {
    const double c = 0.8, theta_min = (2.5 + 5 * H) * M_PI / 180, phi = H * theta_min - M_PI;
    std::vector<double> a(H, 0.0), b(H, 0.0);
    a[H - 1] = c * std::cos(phi), b[H - 1] = c * std::sin(phi);
    EXPECT_NEAR(calc_fourier_minimum(1.0, a, b), 1.0 - c, 1e-12) << H;
    double sampled = HUGE_VAL;
    for (int k = 0; k < 72; ++k) {
      const double th = 2 * M_PI * k / 72;
      sampled = std::min(sampled, 1.0 + c * std::cos(H * th - phi));
    }
    if (H >= 3 && 72 % H == 0) {  // every minimum 2.5° from a sample
      EXPECT_GT(sampled - (1.0 - c), 1e-3) << "72 samples miss the dip (H = " << H << ")";
    }
  }
  // Mixed harmonics against 2·10⁶ angles (their minimum lies within 2e-11 of the true one).
  const std::vector<double> a{0.3, -0.2, 0.05}, b{0.4, 0.1, -0.15};
  double dense = HUGE_VAL;
  for (int k = 0; k < 2000000; ++k) {
    const double th = 2 * M_PI * k / 2000000;
    double v = 0.1;
    for (size_t j = 0; j < a.size(); ++j) v += a[j] * std::cos((j + 1) * th) + b[j] * std::sin((j + 1) * th);
    dense = std::min(dense, v);
  }
  const double m = calc_fourier_minimum(0.1, a, b);
  EXPECT_LE(m, dense + 1e-12);
  EXPECT_GT(m, dense - 1e-9);
  EXPECT_EQ(calc_fourier_minimum(2.5, {}, {}), 2.5);  // a constant
}

}  // namespace
}  // namespace rdyn::validate
