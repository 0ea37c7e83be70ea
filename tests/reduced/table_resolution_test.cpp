// The half-grid miss (reduced/table_resolution.cpp): closed forms on pure harmonics.
#include "reduced/table_resolution.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rdyn::reduced {
namespace {

std::vector<double> sampled(size_t n, double (*f)(double, int), int k) {
  std::vector<double> y(n);
  for (size_t i = 0; i < n; ++i) y[i] = f(2 * M_PI * static_cast<double>(i) / static_cast<double>(n), k);
  return y;
}
double offset_cos(double q, int k) { return 3.0 + std::cos(k * q) + 0.5 * std::sin((k > 1 ? k - 1 : 1) * q); }
double spike(double q, int) { return 1.0 / (1.02 - std::cos(q)); }  // a near-singular m1: harmonics decay as 0.82^k

// 36 points (10°): the half table (18 points) resolves harmonics below 9 exactly; harmonic 9
// and above alias. 3 + cos 8q + ½ sin 7q is exact to rounding; 3 + cos 10q + ½ sin 9q, sampled
// at the odd points, differs from its alias by up to 2·(1 + ½)/4.5 of its peak.
TEST(TableResolution, HalfGridMissIsRoundingBelowTheHalfNyquistAndOrderOneAbove) {
  EXPECT_LT(calc_half_grid_miss(sampled(36, offset_cos, 8)), 1e-13);
  EXPECT_LT(calc_half_grid_miss(sampled(36, offset_cos, 0)), 1e-13);  // constant + ½ sin q
  const double above = calc_half_grid_miss(sampled(36, offset_cos, 10));
  EXPECT_GT(above, 0.3);
  EXPECT_LT(above, 2 * 1.5 / 4.5 + 1e-12);
  EXPECT_GT(calc_half_grid_miss(sampled(36, offset_cos, 10)), kCoarseTableMiss);
  EXPECT_LT(calc_half_grid_miss(sampled(36, offset_cos, 8)), kCoarseTableMiss);
}

// A near-singular peak (harmonics 0.82^k): coarse at 10° (the guard fires), resolved at 1°.
TEST(TableResolution, ASharpPeakIsCoarseAtTenDegreesAndResolvedAtOne) {
  EXPECT_GT(calc_half_grid_miss(sampled(36, spike, 0)), kCoarseTableMiss);
  EXPECT_LT(calc_half_grid_miss(sampled(360, spike, 0)), 1e-6);
}

TEST(TableResolution, OddOrShortColumnsGiveNaNAndZeroGivesZero) {
  EXPECT_TRUE(std::isnan(calc_half_grid_miss(std::vector<double>(35, 1.0))));
  EXPECT_TRUE(std::isnan(calc_half_grid_miss(std::vector<double>(6, 1.0))));
  EXPECT_EQ(calc_half_grid_miss(std::vector<double>(36, 0.0)), 0.0);
}

}  // namespace
}  // namespace rdyn::reduced
