// Fused tables against the functions they interpolate.
#include "reduced/table.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

namespace rdyn::reduced {
namespace {

Samples periodic_samples(int n) {
  Samples s;
  s.step = 2 * M_PI / n;
  s.q0 = 0.0;
  std::vector<double> m1, m2, f;
  for (int i = 0; i < n; ++i) {
    const double q = i * s.step;
    s.q.push_back(q);
    m1.push_back(2.0 + 0.5 * std::sin(q) + 0.2 * std::cos(3 * q));
    m2.push_back(0.5 * (0.5 * std::cos(q) - 0.6 * std::sin(3 * q)));  // ½ dm1/dq
    f.push_back(std::exp(std::sin(q)));                                // smooth, not a trig polynomial
  }
  s.add("m1", m1);
  s.add("m2", m2);
  s.add("f", f);
  return s;
}

double max_error(const Table& t, int col, double (*exact)(double)) {
  double e = 0;
  for (int i = 0; i < 1000; ++i) {
    const double q = -7.0 + 14.0 * i / 999.0;  // across several periods, negative too
    e = std::max(e, std::abs(t.eval(col, q) - exact(q)));
  }
  return e;
}

double f_exact(double q) { return std::exp(std::sin(q)); }
double m1_exact(double q) { return 2.0 + 0.5 * std::sin(q) + 0.2 * std::cos(3 * q); }

TEST(Table, InterpolatesThroughSamplesAndWraps) {
  const auto s = periodic_samples(36);
  for (auto interp : {Interpolation::CubicSpline, Interpolation::Akima, Interpolation::Linear, Interpolation::Fourier}) {
    const Table t = build_table(s, interp);
    for (size_t i = 0; i < s.q.size(); ++i) {
      EXPECT_NEAR(t.eval(2, s.q[i]), s.columns[2][i], 1e-12) << interpolation_name(interp);
      EXPECT_NEAR(t.eval(2, s.q[i] + 4 * M_PI), s.columns[2][i], 1e-12) << interpolation_name(interp);
    }
  }
}

TEST(Table, CubicSplineConvergesAtFourthOrder) {
  const double e10 = max_error(build_table(periodic_samples(36), Interpolation::CubicSpline), 2, f_exact);
  const double e5 = max_error(build_table(periodic_samples(72), Interpolation::CubicSpline), 2, f_exact);
  EXPECT_GT(std::log2(e10 / e5), 3.7);
  EXPECT_LT(std::log2(e10 / e5), 4.5);
  // Linear: second order.
  const double l10 = max_error(build_table(periodic_samples(36), Interpolation::Linear), 2, f_exact);
  const double l5 = max_error(build_table(periodic_samples(72), Interpolation::Linear), 2, f_exact);
  EXPECT_NEAR(std::log2(l10 / l5), 2.0, 0.2);
}

TEST(Table, FourierIsSpectralForSmoothPeriodicColumns) {
  // m1 is a trigonometric polynomial of degree 3: 36 samples represent it exactly, up to the
  // internal ≤ 0.25° cubic resampling (measured 1.6e-11; the former 1° resampling left 4.0e-9).
  EXPECT_LT(max_error(build_table(periodic_samples(36), Interpolation::Fourier), 0, m1_exact), 1e-10);
  const double cubic = max_error(build_table(periodic_samples(36), Interpolation::CubicSpline), 2, f_exact);
  const double fourier = max_error(build_table(periodic_samples(36), Interpolation::Fourier), 2, f_exact);
  EXPECT_LT(fourier, cubic / 100);
}

TEST(Table, EnergyConsistentM2IsHalfTheDerivativeOfM1) {
  const Table t = build_table(periodic_samples(36), Interpolation::CubicSpline, true);
  for (int i = 0; i < 200; ++i) {
    const double q = 0.031 * i;
    EXPECT_NEAR(t.eval(1, q), 0.5 * t.eval_deriv(0, q), 1e-13);
  }
}

TEST(Table, FusedEvaluationMatchesSingleColumns) {
  const Table t = build_table(periodic_samples(36), Interpolation::Akima);
  const int cols[3] = {2, 0, 1};
  double out[3];
  t.eval_cols(1.2345, cols, 3, out);
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(out[k], t.eval(cols[k], 1.2345));
}

TEST(Table, InconsistentSamplesAreRefused) {
  auto ragged = periodic_samples(8);
  ragged.columns[1].pop_back();
  EXPECT_THROW(build_table(ragged, Interpolation::CubicSpline), TableError);
  auto no_step = periodic_samples(8);
  no_step.step = NAN;
  EXPECT_THROW(build_table(no_step, Interpolation::CubicSpline), TableError);
  EXPECT_THROW(build_table(periodic_samples(3), Interpolation::CubicSpline), TableError);
}

TEST(Table, FourierOnAFineGridIsTheCubicTableOfItsSamples) {
  // At ≤ 1° the trigonometric interpolant is resampled on the sample grid itself, where it
  // equals the samples: the table is the cubic one, built without the N² DFT (36 000 points
  // took minutes before), and still interpolates to spline accuracy.
  const auto fine = periodic_samples(36000);
  const auto t0 = std::chrono::steady_clock::now();
  const Table f = build_table(fine, Interpolation::Fourier);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  const Table c = build_table(fine, Interpolation::CubicSpline);
  EXPECT_EQ(f.coef, c.coef);
  EXPECT_LT(max_error(f, 2, f_exact), 1e-12);
  // At 2° it still resamples (refine 2), so it differs from cubic between samples.
  const auto coarse = periodic_samples(180);
  EXPECT_NE(build_table(coarse, Interpolation::Fourier).coef.size(),
            build_table(coarse, Interpolation::CubicSpline).coef.size());
}

}  // namespace
}  // namespace rdyn::reduced
