// Load profiles: the Fourier series in closed form, the periodic cubic table against the
// properties that define it (interpolates, periodic and C² across the wrap, exact on constants).
#include "models/load_profile.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rdyn::models {
namespace {

constexpr double kPi = 3.14159265358979323846;

LoadProfile table_of(double (*f)(double), int rows, double first_deg) {
  std::vector<double> th, v;
  for (int i = 0; i < rows; ++i) {
    th.push_back((first_deg + 360.0 * i / rows) * kPi / 180);
    v.push_back(f(th.back()));
  }
  return make_table_profile("crank", th, v);
}

TEST(LoadProfile, FourierSeriesIsItsClosedForm) {
  LoadProfile p;
  p.a0 = 2.0;
  p.a = {0.5, 0.0, -0.25};
  p.b = {1.5};
  for (double th : {-7.0, -1.0, 0.0, 0.3, 2.0, 12.5}) {
    const double expect = 2.0 + 0.5 * std::cos(th) - 0.25 * std::cos(3 * th) + 1.5 * std::sin(th);
    EXPECT_NEAR(calc_profile(p, th), expect, 1e-14);
  }
  EXPECT_DOUBLE_EQ(calc_profile_bound(p), 2.0 + 0.5 + 0.25 + 1.5);
}

TEST(LoadProfile, TableInterpolatesItsRowsAndIsPeriodic) {
  const auto p = table_of([](double t) { return 3.0 + std::sin(t) + 0.3 * std::cos(2 * t); }, 12, -40);
  for (size_t i = 0; i < p.table_theta_rad.size(); ++i) {
    EXPECT_NEAR(calc_profile(p, p.table_theta_rad[i]), p.table_value[i], 1e-13);
    EXPECT_NEAR(calc_profile(p, p.table_theta_rad[i] + 2 * kPi), p.table_value[i], 1e-12);
    EXPECT_NEAR(calc_profile(p, p.table_theta_rad[i] - 6 * kPi), p.table_value[i], 1e-12);
  }
  // C¹ and C² across every knot, the wrap included (one-sided differences agree).
  const double h = 1e-5;
  for (double x : p.table_theta_rad) {
    const double f0 = calc_profile(p, x), fl = calc_profile(p, x - h), fr = calc_profile(p, x + h);
    const double fl2 = calc_profile(p, x - 2 * h), fr2 = calc_profile(p, x + 2 * h);
    EXPECT_NEAR((f0 - fl) / h, (fr - f0) / h, 1e-4) << x;  // O(h) apart only
    EXPECT_NEAR((f0 - 2 * fl + fl2) / (h * h), (fr2 - 2 * fr + f0) / (h * h), 5e-2) << x;
  }
}

TEST(LoadProfile, TableConvergesToTheSampledFunctionAtFourthOrder) {
  // A periodic cubic spline's error is O(h⁴) (de Boor, ch. V): halving the spacing divides
  // the worst error by about 16.
  auto f = [](double t) { return std::sin(t) + 0.5 * std::cos(3 * t); };
  double err[2] = {0, 0};
  for (int k = 0; k < 2; ++k) {
    const auto p = table_of(f, 36 << k, 5);
    for (int i = 0; i < 2000; ++i) {
      const double th = 2 * kPi * i / 2000;
      err[k] = std::max(err[k], std::abs(calc_profile(p, th) - f(th)));
    }
  }
  EXPECT_LT(err[0], 1e-3);
  EXPECT_GT(err[0] / err[1], 12.0);
  EXPECT_LT(err[0] / err[1], 20.0);
}

TEST(LoadProfile, ConstantTableIsExactlyConstantAndBoundHolds) {
  const auto c = table_of([](double) { return -4.25; }, 5, 0);
  for (int i = 0; i < 100; ++i) EXPECT_NEAR(calc_profile(c, 0.1 * i - 3), -4.25, 1e-14);
  EXPECT_DOUBLE_EQ(calc_profile_bound(c), 4.25);
  // A peaked table overshoots between rows; the bound covers it.
  std::vector<double> th{0, 0.5, 1.0, 3.0}, v{0, 10, 0, 0};
  const auto p = make_table_profile("crank", th, v);
  double m = 0;
  for (int i = 0; i < 10000; ++i) m = std::max(m, std::abs(calc_profile(p, 2 * kPi * i / 10000)));
  EXPECT_GT(m, 10.0);  // the spline does overshoot here
  EXPECT_GE(calc_profile_bound(p), m);
}

}  // namespace
}  // namespace rdyn::models
