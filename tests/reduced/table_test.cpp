// Fused tables against the functions they interpolate.
#include "reduced/table.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>

#include <gsl/gsl_spline.h>

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

// The table records the interpolant it was built with: a range table (no period) takes the
// not-a-knot cubic spline in place of fourier, and run.json reports that, not the option.
TEST(Table, RecordsTheInterpolantItBuilt) {
  Samples per = periodic_samples(36);
  EXPECT_EQ(build_table(per, Interpolation::Fourier).fit, "fourier");
  EXPECT_EQ(build_table(per, Interpolation::CubicSpline).fit, "cubic");
  Samples range = per;
  range.periodic = false;
  EXPECT_EQ(build_table(range, Interpolation::Fourier).fit, "cubic (not-a-knot)");
  EXPECT_EQ(build_table(range, Interpolation::Akima).fit, "akima");
}

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

// The periodic cubic table is solved directly (one factorization for every column); GSL's
// cspline_periodic, which solves the same equations its own way, is the independent route.
// Between the knots, across the wrap and on grids of 4 (the smallest), 5, 36 and 1440 points.
TEST(Table, PeriodicCubicEqualsGslPeriodicSpline) {
  for (int n : {4, 5, 36, 1440}) {
    const auto s = periodic_samples(n);
    const Table t = build_table(s, Interpolation::CubicSpline);
    std::vector<double> x(n + 1), y(n + 1);
    for (int i = 0; i <= n; ++i) x[i] = i * s.step;
    std::unique_ptr<gsl_spline, decltype(&gsl_spline_free)> sp(gsl_spline_alloc(gsl_interp_cspline_periodic, n + 1),
                                                               gsl_spline_free);
    for (int c = 0; c < 3; ++c) {
      for (int i = 0; i <= n; ++i) y[i] = s.columns[c][i % n];
      ASSERT_EQ(gsl_spline_init(sp.get(), x.data(), y.data(), n + 1), 0);
      double worst = 0.0, scale = 0.0;
      for (int k = 0; k < 4000; ++k) {
        const double q = 2 * M_PI * (k + 0.37) / 4000;
        const double ref = gsl_spline_eval(sp.get(), q, nullptr);
        worst = std::max(worst, std::abs(t.eval(c, q) - ref));
        worst = std::max(worst, std::abs(t.eval(c, q - 2 * M_PI) - ref));  // the wrap
        worst = std::max(worst, std::abs(t.eval_deriv(c, q) - gsl_spline_eval_deriv(sp.get(), q, nullptr)) * s.step);
        scale = std::max(scale, std::abs(ref));
      }
      EXPECT_LT(worst, 1e-13 * scale) << n << " points, column " << c;
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

// The former O(N·M) direct DFT resampling (reduced/table.cpp before issue #11), kept as the
// reference the FFT route must reproduce.
Samples direct_dft_resample(const Samples& s, int refine) {
  const int n = static_cast<int>(s.q.size()), m = n * refine;
  Samples out = s;
  out.step = s.step * n / m;
  out.q.resize(m);
  for (int i = 0; i < m; ++i) out.q[i] = s.q0 + i * out.step;
  const int kmax = n / 2;
  for (size_t c = 0; c < s.columns.size(); ++c) {
    std::vector<double> a(kmax + 1, 0.0), b(kmax + 1, 0.0);
    for (int k = 0; k <= kmax; ++k) {
      for (int i = 0; i < n; ++i) {
        a[k] += s.columns[c][i] * std::cos(2 * M_PI * k * i / n);
        b[k] += s.columns[c][i] * std::sin(2 * M_PI * k * i / n);
      }
      const double w = (k == 0 || (n % 2 == 0 && k == kmax)) ? 1.0 / n : 2.0 / n;
      a[k] *= w, b[k] *= w;
    }
    if (n % 2 == 0) b[kmax] = 0.0;
    auto& col = out.columns[c];
    col.assign(m, 0.0);
    for (int i = 0; i < m; ++i)
      for (int k = 0; k <= kmax; ++k) {
        const double ph = 2 * M_PI * k * (static_cast<double>(i) / refine) / n;
        col[i] += a[k] * std::cos(ph) + b[k] * std::sin(ph);
      }
  }
  return out;
}

// Random smooth periodic columns: a random trigonometric series with decaying amplitudes
// (up to degree 40, above the Nyquist degree of the coarse grids, so aliasing is exercised).
Samples random_smooth_samples(int n, unsigned seed, double q0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Samples s;
  s.step = 2 * M_PI / n;
  s.q0 = q0;
  for (int i = 0; i < n; ++i) s.q.push_back(q0 + i * s.step);
  for (int c = 0; c < 3; ++c) {
    double a[41], b[41];
    for (int k = 0; k <= 40; ++k) a[k] = u(rng) * std::exp(-0.15 * k), b[k] = u(rng) * std::exp(-0.15 * k);
    std::vector<double> v(n);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k <= 40; ++k) v[i] += a[k] * std::cos(k * s.q[i]) + b[k] * std::sin(k * s.q[i]);
    s.add("c" + std::to_string(c), v);
  }
  return s;
}

TEST(Table, FourierByFftMatchesTheDirectDftForOddAndEvenGrids) {
  // Odd and even N, prime N (GSL's generic factor), grids from 15° to 0.3° (refine 60 to 2),
  // and a first grid point off zero.
  for (int n : {24, 25, 36, 37, 71, 72, 360, 1200}) {
    const auto s = random_smooth_samples(n, 100 + n, n % 2 ? 0.3 : 0.0);
    const int refine = std::max(1, static_cast<int>(std::ceil(s.step / (M_PI / 720.0) - 1e-9)));
    ASSERT_GE(refine, 2) << n;
    const Table fft = build_table(s, Interpolation::Fourier);
    const Table dft = build_table(direct_dft_resample(s, refine), Interpolation::CubicSpline);
    ASSERT_EQ(fft.coef.size(), dft.coef.size()) << n;
    EXPECT_DOUBLE_EQ(fft.step, dft.step);
    for (int c = 0; c < 3; ++c) {
      double scale = 0, diff = 0;
      for (int iv = 0; iv < fft.intervals; ++iv) {
        const size_t at = (static_cast<size_t>(iv) * fft.cols + c) * 4;
        scale = std::max(scale, std::abs(dft.coef[at]));
        diff = std::max(diff, std::abs(fft.coef[at] - dft.coef[at]));
      }
      EXPECT_LT(diff, 1e-12 * scale) << "N = " << n << ", column " << c;
      // Values between the fine grid points too (the cubic coefficients agree, not only the knots).
      for (int i = 0; i < 200; ++i) {
        const double q = s.q0 + 2 * M_PI * (i + 0.37) / 200;
        EXPECT_NEAR(fft.eval(c, q), dft.eval(c, q), 1e-12 * scale) << "N = " << n << ", q = " << q;
      }
    }
  }
}

TEST(Table, FourierReproducesASampledTrigonometricPolynomialExactly) {
  // A degree-4 trigonometric polynomial sampled at N = 9 (odd) and N = 10 (even, whose Nyquist
  // degree 5 is absent) is its own interpolant: the fine grid values are the polynomial.
  for (int n : {9, 10}) {
    Samples s;
    s.step = 2 * M_PI / n;
    std::vector<double> v;
    auto p = [](double q) { return 1.5 + std::cos(q) - 0.5 * std::sin(2 * q) + 0.25 * std::cos(4 * q + 0.3); };
    for (int i = 0; i < n; ++i) s.q.push_back(i * s.step), v.push_back(p(i * s.step));
    s.add("p", v);
    const Table t = build_table(s, Interpolation::Fourier);
    ASSERT_EQ(t.step, 2 * M_PI / t.intervals);
    for (int i = 0; i < t.intervals; ++i) EXPECT_NEAR(t.eval(0, i * t.step), p(i * t.step), 1e-13) << n;
  }
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

// The interval and offset as first written (std::floor, wrap by %): locate's faster floor and
// wrap must give the same index and the same dx bit for bit. `divide`: u = (q − q0)/step as
// first written; otherwise times the stored 1/step, as locate computes it.
int locate_reference(const Table& t, double q, double& dx, bool divide = false) {
  const double u = divide ? (q - t.q0) / t.step : (q - t.q0) * t.inv_step;
  const double fl = std::floor(u);
  long i = static_cast<long>(fl);
  dx = (u - fl) * t.step;
  if (!t.periodic) {  // the first and last cubics extrapolate just outside the range
    if (i < 0) dx = u * t.step;
    if (i >= t.intervals) dx = (u - (t.intervals - 1)) * t.step;
    return static_cast<int>(std::clamp(i, 0L, static_cast<long>(t.intervals - 1)));
  }
  i %= t.intervals;
  if (i < 0) i += t.intervals;
  return static_cast<int>(i);
}

// The packed evaluation (one locate, contiguous coefficients, vectorized across columns) is
// the per-column evaluation bit for bit: at grid points and one ulp either side of them,
// many periods away, negative q, and with a column listed twice; periodic and range tables.
TEST(Table, ColumnBlockEqualsPerColumnEvaluationBitForBit) {
  auto range = periodic_samples(36);
  range.periodic = false;
  for (const Table& t : {build_table(periodic_samples(36), Interpolation::Fourier),
                         build_table(periodic_samples(36), Interpolation::Akima), build_table(range, Interpolation::CubicSpline)}) {
    const std::vector<int> cols = {2, 0, 1, 0};
    const ColumnBlock b = make_column_block(t, cols);
    std::vector<double> qs;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> any(-60.0, 60.0);
    for (int i = 0; i < 2000; ++i) qs.push_back(any(rng));
    for (int k = -80; k <= 80; ++k) {
      const double g = t.q0 + k * t.step;
      qs.insert(qs.end(), {g, std::nextafter(g, -INFINITY), std::nextafter(g, INFINITY)});
    }
    if (!t.periodic)  // a range table is evaluated within its range only (callers check in_range)
      qs.erase(std::remove_if(qs.begin(), qs.end(), [&](double q) { return !t.in_range(q); }), qs.end());
    ASSERT_GT(qs.size(), 100u);
    for (double q : qs) {
      double out[4], fused[4];
      eval_block(t, b, q, out);
      t.eval_cols(q, cols.data(), 4, fused);
      for (int k = 0; k < 4; ++k) {
        ASSERT_EQ(out[k], t.eval(cols[k], q)) << "q = " << q << ", column " << cols[k] << ", fit " << t.fit;
        ASSERT_EQ(out[k], fused[k]);
      }
      double dx, dx_ref;
      ASSERT_EQ(t.locate(q, dx), locate_reference(t, q, dx_ref)) << "q = " << q;
      ASSERT_EQ(dx, dx_ref) << "q = " << q;
      // Multiplying by 1/step instead of dividing moves the point by rounding only: the same
      // interval with dx within 1e-12 of a step, or (q on a grid point) the neighbouring one with
      // dx at the other end.
      double dx_div;
      const int i_div = locate_reference(t, q, dx_div, true);
      const int i = t.locate(q, dx);
      const double tol = 1e-12 * t.step * (1 + std::abs(q));
      if (i == i_div) {
        ASSERT_NEAR(dx, dx_div, tol) << "q = " << q;
      } else {
        const int n = t.intervals;
        const bool next = t.periodic ? (i_div + 1) % n == i : i_div + 1 == i;
        const bool prev = t.periodic ? (i + 1) % n == i_div : i + 1 == i_div;
        ASSERT_TRUE((next && dx <= tol && dx_div >= t.step - tol) || (prev && dx_div <= tol && dx >= t.step - tol))
            << "q = " << q << " intervals " << i << " vs " << i_div;
      }
    }
  }
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
