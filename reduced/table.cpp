#include "reduced/table.hpp"

#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_fft_halfcomplex.h>
#include <gsl/gsl_fft_real.h>
#include <gsl/gsl_spline.h>

namespace rdyn::reduced {

Interpolation parse_interpolation(const std::string& name) {
  if (name == "cubic") return Interpolation::CubicSpline;
  if (name == "akima") return Interpolation::Akima;
  if (name == "linear") return Interpolation::Linear;
  if (name == "fourier") return Interpolation::Fourier;
  throw TableError("unknown interpolation '" + name + "' (cubic, akima, linear, fourier)");
}

std::string interpolation_name(Interpolation i) {
  switch (i) {
    case Interpolation::CubicSpline: return "cubic";
    case Interpolation::Akima: return "akima";
    case Interpolation::Linear: return "linear";
    case Interpolation::Fourier: return "fourier";
  }
  return "?";
}

namespace {

// Trigonometric interpolant of N equispaced samples over one period, evaluated on a grid
// `refine` times finer. For even N the Nyquist term is a cosine with half weight, so the
// interpolant is real and passes through every sample:
//   f(x) = Σ_{k=0}^{N/2} a_k cos(2πkx/N) + b_k sin(2πkx/N),  x in sample units,
//   a_k − i b_k = w_k X_k,  X_k = Σ_j y_j e^{−2πijk/N},  w_k = 2/N (1/N for k = 0 and even-N Nyquist).
// X_k by GSL's mixed-radix real FFT (any N; O(N log N) for N with small prime factors), and
// f on the fine grid (M = refine·N points) by zero-padding the spectrum to M and one inverse
// real FFT: the backward sum Σ Z_k e^{+2πiik/M} with Z_k = (a_k − i b_k)/2 (Z_0 = a_0) is f at
// x = i/refine. O(M log M) per column instead of the direct DFT's O(N·M) (issue #11, item 5).
Samples fourier_resample(const Samples& s, int refine) {
  const int n = static_cast<int>(s.q.size()), m = n * refine;
  const double period = s.step * n;
  Samples out = s;
  out.step = period / m;
  out.q.resize(m);
  for (int i = 0; i < m; ++i) out.q[i] = s.q0 + i * out.step;
  const int kmax = n / 2;
  using RealTable = std::unique_ptr<gsl_fft_real_wavetable, decltype(&gsl_fft_real_wavetable_free)>;
  using HalfTable = std::unique_ptr<gsl_fft_halfcomplex_wavetable, decltype(&gsl_fft_halfcomplex_wavetable_free)>;
  using Work = std::unique_ptr<gsl_fft_real_workspace, decltype(&gsl_fft_real_workspace_free)>;
  const RealTable forward(gsl_fft_real_wavetable_alloc(n), gsl_fft_real_wavetable_free);
  const HalfTable backward(gsl_fft_halfcomplex_wavetable_alloc(m), gsl_fft_halfcomplex_wavetable_free);
  const Work work_n(gsl_fft_real_workspace_alloc(n), gsl_fft_real_workspace_free);
  const Work work_m(gsl_fft_real_workspace_alloc(m), gsl_fft_real_workspace_free);
  if (!forward || !backward || !work_n || !work_m) throw TableError("fourier interpolation: out of memory for the FFT");
  gsl_set_error_handler_off();
  std::vector<double> x(n);
  for (size_t c = 0; c < s.columns.size(); ++c) {
    x = s.columns[c];
    if (gsl_fft_real_transform(x.data(), 1, n, forward.get(), work_n.get()) != GSL_SUCCESS)
      throw TableError("fourier interpolation: GSL's FFT failed on column '" + s.names[c] + "'");
    // x is in GSL's half-complex order: x[0] = Re X_0, x[2k−1] = Re X_k, x[2k] = Im X_k
    // (k < N/2), x[N−1] = Re X_{N/2} for even N. Z_k = X_k/N (the Nyquist term X_{N/2}/(2N)),
    // placed in the half-complex order of length M (k ≤ N/2 < M/2 since refine ≥ 2).
    auto& col = out.columns[c];
    col.assign(m, 0.0);
    col[0] = x[0] / n;
    for (int k = 1; k <= kmax; ++k) {
      if (n % 2 == 0 && k == kmax) {
        col[2 * k - 1] = x[n - 1] / (2.0 * n);  // real: b_{N/2} = 0
      } else {
        col[2 * k - 1] = x[2 * k - 1] / n;
        col[2 * k] = x[2 * k] / n;
      }
    }
    if (gsl_fft_halfcomplex_backward(col.data(), 1, m, backward.get(), work_m.get()) != GSL_SUCCESS)
      throw TableError("fourier interpolation: GSL's inverse FFT failed on column '" + s.names[c] + "'");
  }
  return out;
}

// Periodic cubic spline on a uniform grid of n points (period n·h), every column at once: the
// second derivatives M_i solve the cyclic system M_{i−1} + 4 M_i + M_{i+1} = 6 (y_{i+1} − 2 y_i +
// y_{i−1})/h², the equations of GSL's cspline_periodic, whose matrix is the same for every
// column. Sherman–Morrison on the cyclic corner (Press et al., Numerical Recipes §2.7): the
// tridiagonal part is factored once (Thomas multipliers) and its correction vector solved
// once, so a column costs two sweeps. Building the cubic from GSL's spline instead (an init
// and two evaluations per interval and column) was 2.6 ms of the 10° bicycle's fourier table
// (21 columns resampled to 1440 points), 25 % of a calibration.
// Writes each interval's cubic a + b dx + c dx² + d dx³ into coef[(iv·cols + col)·4].
void periodic_cubic_coefficients(const std::vector<std::vector<double>>& columns, double h, std::vector<double>& coef) {
  if (columns.empty()) return;
  const int n = static_cast<int>(columns[0].size()), cols = static_cast<int>(columns.size());
  // Tridiagonal T = tridiag(1, 4, 1) with T_00 = 4 − γ and T_{n−1,n−1} = 4 − 1/γ, γ = −4, and
  // the corner vector v = (γ, 0, …, 0, 1): A = T + v wᵀ, w = (1, 0, …, 0, 1/γ).
  const double gamma = -4.0;
  std::vector<double> diag(n, 4.0), inv(n), low(n);  // Thomas: low_i = 1/piv_{i−1}, inv_i = 1/piv_i
  diag[0] = 4.0 - gamma;
  diag[n - 1] = 4.0 - 1.0 / gamma;
  double piv = diag[0];
  inv[0] = 1.0 / piv;
  for (int i = 1; i < n; ++i) {
    low[i] = inv[i - 1];  // the multiplier of row i (sub-diagonal 1 over the previous pivot)
    piv = diag[i] - low[i];  // the super-diagonal is 1
    inv[i] = 1.0 / piv;
  }
  auto thomas = [&](std::vector<double>& x) {  // x ← T⁻¹ x
    for (int i = 1; i < n; ++i) x[i] -= low[i] * x[i - 1];
    x[n - 1] *= inv[n - 1];
    for (int i = n - 2; i >= 0; --i) x[i] = (x[i] - x[i + 1]) * inv[i];
  };
  std::vector<double> z(n, 0.0);
  z[0] = gamma;
  z[n - 1] = 1.0;
  thomas(z);
  const double z_dot = 1.0 + z[0] + z[n - 1] / gamma;
  std::vector<double> M(n);
  const double k = 6.0 / (h * h);
  for (int c = 0; c < cols; ++c) {
    const auto& y = columns[c];
    // The wrapped neighbours at the ends, the others without a modulo (an integer division per
    // point, ~60 k a fourier table: its CPU time, not its instructions).
    M[0] = k * (y[1] - 2 * y[0] + y[n - 1]);
    for (int i = 1; i + 1 < n; ++i) M[i] = k * (y[i + 1] - 2 * y[i] + y[i - 1]);
    M[n - 1] = k * (y[0] - 2 * y[n - 1] + y[n - 2]);
    thomas(M);
    const double f = (M[0] + M[n - 1] / gamma) / z_dot;
    for (int i = 0; i < n; ++i) M[i] -= f * z[i];
    for (int iv = 0; iv < n; ++iv) {
      const int next = iv + 1 < n ? iv + 1 : 0;
      double* cf = &coef[(static_cast<size_t>(iv) * cols + c) * 4];
      cf[0] = y[iv];
      cf[1] = (y[next] - y[iv]) / h - h * (2 * M[iv] + M[next]) / 6;
      cf[2] = M[iv] / 2;
      cf[3] = (M[next] - M[iv]) / (6 * h);
    }
  }
}

// Not-a-knot cubic spline on a uniform grid (de Boor, A Practical Guide to Splines, ch. IV):
// second derivatives M_i from M_{i−1} + 4 M_i + M_{i+1} = 6 (y_{i+1} − 2 y_i + y_{i−1})/h², with the
// third derivative continuous at the second and the second-to-last points (M_0 − 2 M_1 + M_2 = 0,
// likewise at the end), which reduces rows 1 and n−2 to 6 M_1 = rhs_1, 6 M_{n−2} = rhs_{n−2}. Its
// error is O(h⁴) up to the ends, where GSL's natural spline (M = 0 at the ends) is O(h²).
// Writes each interval's cubic a + b dx + c dx² + d dx³ into coef[(iv·cols + col)·4].
void not_a_knot_coefficients(const std::vector<double>& y, double h, int col, int cols, std::vector<double>& coef) {
  const int n = static_cast<int>(y.size());
  std::vector<double> rhs(n, 0.0), M(n, 0.0);
  for (int i = 1; i + 1 < n; ++i) rhs[i] = 6.0 * (y[i + 1] - 2 * y[i] + y[i - 1]) / (h * h);
  M[1] = rhs[1] / 6.0;
  M[n - 2] = rhs[n - 2] / 6.0;
  // Rows 2..n−3: tridiagonal (1, 4, 1) with M_1 and M_{n−2} known (Thomas algorithm).
  const int lo = 2, hi = n - 3;
  if (hi >= lo) {
    const int m = hi - lo + 1;
    std::vector<double> cp(m), dp(m);
    for (int k = 0; k < m; ++k) {
      double r = rhs[lo + k];
      if (k == 0) r -= M[1];
      if (k == m - 1) r -= M[n - 2];
      const double denom = 4.0 - (k > 0 ? cp[k - 1] : 0.0);
      cp[k] = 1.0 / denom;
      dp[k] = (r - (k > 0 ? dp[k - 1] : 0.0)) / denom;
    }
    for (int k = m - 1; k >= 0; --k) M[lo + k] = dp[k] - (k + 1 < m ? cp[k] * M[lo + k + 1] : 0.0);
  }
  M[0] = 2 * M[1] - M[2];
  M[n - 1] = 2 * M[n - 2] - M[n - 3];
  for (int iv = 0; iv + 1 < n; ++iv) {
    double* cf = &coef[(static_cast<size_t>(iv) * cols + col) * 4];
    cf[0] = y[iv];
    cf[1] = (y[iv + 1] - y[iv]) / h - h * (2 * M[iv] + M[iv + 1]) / 6.0;
    cf[2] = M[iv] / 2.0;
    cf[3] = (M[iv + 1] - M[iv]) / (6.0 * h);
  }
}

}  // namespace

namespace {

// a + b dx + c dx² + d dx³ by Estrin's scheme, (a + b dx) + dx² (c + d dx): two levels of
// multiply-add instead of Horner's three, which matters on the RK4 chain, where each stage's
// table lookup waits for the previous stage (issue #11 item 6). eval_block spells out the same
// operations.
inline double cubic(double a, double b, double c, double d, double dx) {
  return (a + dx * b) + (dx * dx) * (c + dx * d);
}

}  // namespace

int Table::locate(double q, double& dx) const {
  const double u = (q - q0) * inv_step;
  // NaN, or beyond the exactly representable integers: no interval (the cast would be undefined);
  // dx is NaN for NaN so callers see a non-finite value and report it.
  if (!(std::abs(u) < 4.0e18)) {
    dx = u - u;
    return 0;
  }
  // floor(u) by truncation and one correction (exact for |u| < 2^63, the same value as
  // std::floor, which without SSE4.1 is a library call on the hot path).
  long i = static_cast<long>(u);
  if (static_cast<double>(i) > u) --i;
  const double fl = static_cast<double>(i);
  dx = (u - fl) * step;
  if (periodic) {
    // Wrap the interval index (integer arithmetic: no fmod; the division only past the first
    // period).
    if (i >= 0 && i < intervals) return static_cast<int>(i);
    i %= intervals;
    if (i < 0) i += intervals;
    return static_cast<int>(i);
  }
  if (i < 0) {
    dx = (u - 0.0) * step;  // extrapolate the first cubic (callers check in_range)
    return 0;
  }
  if (i >= intervals) {
    dx = (u - (intervals - 1)) * step;
    return intervals - 1;
  }
  return static_cast<int>(i);
}

bool Table::in_range(double q) const {
  return periodic || (q >= q0 - 1e-12 * step && q <= q0 + intervals * step * (1 + 1e-12));
}

double Table::eval(int col, double q) const {
  double dx;
  const double* c = &coef[(static_cast<size_t>(locate(q, dx)) * cols + col) * 4];
  return cubic(c[0], c[1], c[2], c[3], dx);
}

double Table::eval_deriv(int col, double q) const {
  double dx;
  const double* c = &coef[(static_cast<size_t>(locate(q, dx)) * cols + col) * 4];
  return c[1] + dx * (2 * c[2] + dx * 3 * c[3]);
}

void Table::eval_cols(double q, const int* idx, int n, double* out) const {
  double dx;
  const double* row = &coef[static_cast<size_t>(locate(q, dx)) * cols * 4];
  for (int k = 0; k < n; ++k) {
    const double* c = row + idx[k] * 4;
    out[k] = cubic(c[0], c[1], c[2], c[3], dx);
  }
}

ColumnBlock make_column_block(const Table& t, const std::vector<int>& cols) {
  ColumnBlock b;
  b.cols = cols;
  const size_t n = cols.size();
  b.coef.assign(static_cast<size_t>(t.intervals) * 4 * n, 0.0);
  for (int iv = 0; iv < t.intervals; ++iv)
    for (size_t k = 0; k < n; ++k)
      for (int p = 0; p < 4; ++p)
        b.coef[(static_cast<size_t>(iv) * 4 + p) * n + k] = t.coef[(static_cast<size_t>(iv) * t.cols + cols[k]) * 4 + p];
  return b;
}

void eval_block(const Table& t, const ColumnBlock& b, double q, double* __restrict out) {
  double dx;
  const size_t n = b.cols.size();
  const double* __restrict c0 = &b.coef[static_cast<size_t>(t.locate(q, dx)) * 4 * n];
  const double* __restrict c1 = c0 + n;
  const double* __restrict c2 = c1 + n;
  const double* __restrict c3 = c2 + n;
  const double dx2 = dx * dx;
  // As Table::eval_cols (cubic(): the same operations, so the same bits).
  for (size_t k = 0; k < n; ++k) out[k] = (c0[k] + dx * c1[k]) + dx2 * (c2[k] + dx * c3[k]);
}

int Table::column(const std::string& name) const {
  for (int c = 0; c < cols; ++c)
    if (names[c] == name) return c;
  return -1;
}

namespace {

// Every other interpolant through GSL (periodic Akima, linear) and the range tables' not-a-knot
// cubic: each interval's exact cubic from four values inside it.
void interpolant_coefficients(const Samples& s, Interpolation interp, Table& t) {
  const int n = static_cast<int>(s.q.size());
  const gsl_interp_type* type = nullptr;
  switch (interp) {
    case Interpolation::CubicSpline: type = s.periodic ? gsl_interp_cspline_periodic : gsl_interp_cspline; break;
    case Interpolation::Akima: type = s.periodic ? gsl_interp_akima_periodic : gsl_interp_akima; break;
    case Interpolation::Linear: type = gsl_interp_linear; break;
    case Interpolation::Fourier: break;  // build_table resamples it to a cubic table
  }
  // Periodic interpolants take the first point again at q0 + period.
  const int m = s.periodic ? n + 1 : n;
  std::vector<double> x(m), y(m);
  for (int i = 0; i < m; ++i) x[i] = s.q0 + i * s.step;
  std::unique_ptr<gsl_spline, decltype(&gsl_spline_free)> sp(gsl_spline_alloc(type, m), gsl_spline_free);
  // GSL refuses (returns null) fewer points than the type needs (Akima: 5).
  if (!sp)
    throw TableError(fmt::format("{} interpolation needs more than the table's {} grid points",
                                 interpolation_name(interp), n));
  std::unique_ptr<gsl_interp_accel, decltype(&gsl_interp_accel_free)> acc(gsl_interp_accel_alloc(),
                                                                         gsl_interp_accel_free);
  gsl_set_error_handler_off();
  for (int c = 0; c < t.cols; ++c) {
    for (int i = 0; i < m; ++i) y[i] = s.columns[c][i % n];
    if (!s.periodic && interp == Interpolation::CubicSpline) {
      // Range tables: not-a-knot ends (O(h⁴) to the edges; measured in docs/theory.md).
      not_a_knot_coefficients(y, s.step, c, t.cols, t.coef);
      continue;
    }
    if (gsl_spline_init(sp.get(), x.data(), y.data(), m) != GSL_SUCCESS)
      throw TableError("GSL could not build the interpolant of column '" + s.names[c] + "'");
    // Exact cubic per interval from four values inside it (s = 0, 1/3, 2/3, 1): the
    // interpolants are piecewise cubic, so this reproduces them up to rounding.
    for (int iv = 0; iv < t.intervals; ++iv) {
      const double h = s.step, xa = x[iv];
      const double f0 = y[iv], f3 = y[iv + 1];
      const double f1 = gsl_spline_eval(sp.get(), xa + h / 3, acc.get());
      const double f2 = gsl_spline_eval(sp.get(), xa + 2 * h / 3, acc.get());
      // Inverse Vandermonde of s = 0, 1/3, 2/3, 1 (Newton divided differences).
      const double A = f0;
      const double B = (-11 * f0 + 18 * f1 - 9 * f2 + 2 * f3) / 2;
      const double C = (18 * f0 - 45 * f1 + 36 * f2 - 9 * f3) / 2;
      const double D = (-9 * f0 + 27 * f1 - 27 * f2 + 9 * f3) / 2;
      double* cf = &t.coef[(static_cast<size_t>(iv) * t.cols + c) * 4];
      cf[0] = A;
      cf[1] = B / h;
      cf[2] = C / (h * h);
      cf[3] = D / (h * h * h);
    }
  }
}

}  // namespace

Table build_table(const Samples& samples, Interpolation interp, bool energy_consistent_m2) {
  // Consistent samples before any allocation (hand-made samples skip the reader's checks).
  const size_t npts = samples.q.size();
  if (npts < 4) throw TableError("a reduced table needs at least 4 grid points");
  if (!(std::isfinite(samples.step) && samples.step > 0) || !std::isfinite(samples.q0))
    throw TableError("a reduced table needs a finite positive grid step and a finite first point");
  if (samples.columns.size() != samples.names.size())
    throw TableError("reduced table: columns and names differ in number");
  for (size_t c = 0; c < samples.columns.size(); ++c)
    if (samples.columns[c].size() != npts)
      throw TableError(fmt::format("reduced table: column '{}' has {} values for {} grid points", samples.names[c],
                                   samples.columns[c].size(), npts));
  if (interp == Interpolation::Fourier) {
    // A range table has no period: the trigonometric interpolant does not apply, and the
    // not-a-knot cubic spline (the range tables' own, O(h⁴)) stands in for it.
    if (!samples.periodic) return build_table(samples, Interpolation::CubicSpline, energy_consistent_m2);
    // Resampled at ≤ 0.25°: the cubic table's own error (∝ h⁴) then sits ~1e-11 of a
    // parameter's size, below the full-model reference's accuracy; at 1° it was a floor of
    // ~1.5e-9 that every grid from 10° to 1° hit (issue #14, measured on exp(sin q)).
    const int refine = std::max(1, static_cast<int>(std::ceil(samples.step / (M_PI / 720.0) - 1e-9)));
    // At 0.25° or finer the resampling grid is the sample grid, where the trigonometric
    // interpolant equals the samples: skip the FFTs and build the cubic table from the samples
    // themselves.
    Table t = refine == 1 ? build_table(samples, Interpolation::CubicSpline, energy_consistent_m2)
                          : build_table(fourier_resample(samples, refine), Interpolation::CubicSpline,
                                        energy_consistent_m2);
    t.fit = interpolation_name(Interpolation::Fourier);
    return t;
  }
  const Samples& s = samples;
  const int n = static_cast<int>(s.q.size());
  if (n < 4) throw TableError("a reduced table needs at least 4 grid points");
  Table t;
  t.periodic = s.periodic;
  t.q0 = s.q0;
  t.step = s.step;
  t.inv_step = 1.0 / s.step;
  t.period = s.periodic ? s.step * n : 0.0;
  t.intervals = s.periodic ? n : n - 1;
  t.cols = static_cast<int>(s.names.size());
  t.names = s.names;
  t.fit = !s.periodic && interp == Interpolation::CubicSpline ? "cubic (not-a-knot)" : interpolation_name(interp);
  t.coef.assign(static_cast<size_t>(t.intervals) * t.cols * 4, 0.0);

  if (s.periodic && interp == Interpolation::CubicSpline) {
    periodic_cubic_coefficients(s.columns, s.step, t.coef);
  } else {
    interpolant_coefficients(s, interp, t);
  }
  if (energy_consistent_m2) {
    // target = scale · d/dq source on every interval:
    // d/dq (a + b dx + c dx² + d dx³) = b + 2c dx + 3d dx².
    auto set_derivative = [&](int src, int dst, double scale) {
      for (int iv = 0; iv < t.intervals; ++iv) {
        const double* a = &t.coef[(static_cast<size_t>(iv) * t.cols + src) * 4];
        double* b = &t.coef[(static_cast<size_t>(iv) * t.cols + dst) * 4];
        b[0] = scale * a[1];
        b[1] = scale * 2 * a[2];
        b[2] = scale * 3 * a[3];
        b[3] = 0.0;
      }
    };
    set_derivative(s.require("m1"), s.require("m2"), 0.5);  // Eksergian: m2 = ½ dm1/dq
    // Q_cons = −dV/dq, so the potential part is exactly conservative too.
    if (s.column("V") >= 0 && s.column("Q_cons") >= 0) set_derivative(s.require("V"), s.require("Q_cons"), -1.0);
  }
  return t;
}

}  // namespace rdyn::reduced
