#include "engine/least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace rdyn::engine {

using namespace SimTK;

namespace {

// Householder QR with column pivoting of the column-major m × n matrix a (m ≥ n), in place
// (LAPACK dgeqp3's factorization, unblocked): at step k the remaining column of largest norm is
// swapped in and reflected onto e_k. Returns |R_nn| / |R_11| (0 for a zero matrix).
double pivoted_qr(int m, int n, std::vector<double>& a, std::vector<double>& beta, std::vector<int>& perm) {
  auto at = [&](int i, int j) -> double& { return a[static_cast<size_t>(j) * m + i]; };
  beta.assign(n, 0.0);
  perm.resize(n);
  for (int j = 0; j < n; ++j) perm[j] = j;
  double r11 = 0.0, rnn = 0.0;
  for (int k = 0; k < n; ++k) {
    int best = k;
    double best_norm = -1.0;
    for (int j = k; j < n; ++j) {  // n ≤ ~20: recomputed norms, no downdating
      double s = 0.0;
      for (int i = k; i < m; ++i) s += at(i, j) * at(i, j);
      if (s > best_norm) best_norm = s, best = j;
    }
    if (best != k) {
      for (int i = 0; i < m; ++i) std::swap(at(i, k), at(i, best));
      std::swap(perm[k], perm[best]);
    }
    const double norm = std::sqrt(best_norm);
    if (norm == 0.0) return 0.0;
    const double alpha = at(k, k) >= 0 ? -norm : norm;  // R_kk, the sign that avoids cancellation
    const double v0 = at(k, k) - alpha;
    for (int i = k + 1; i < m; ++i) at(i, k) /= v0;  // v = (1, a_k+1.. / v0)
    beta[k] = -v0 / alpha;                           // 2 / vᵀv
    at(k, k) = alpha;
    for (int j = k + 1; j < n; ++j) {  // the remaining columns: (I − β v vᵀ) a_j
      double d = at(k, j);
      for (int i = k + 1; i < m; ++i) d += at(i, k) * at(i, j);
      d *= beta[k];
      at(k, j) -= d;
      for (int i = k + 1; i < m; ++i) at(i, j) -= d * at(i, k);
    }
    if (k == 0) r11 = std::abs(alpha);
    rnn = std::abs(alpha);
  }
  return r11 > 0 ? rnn / r11 : 0.0;
}

// The singular values of the column-major p × k matrix b (p ≥ k) by one-sided Jacobi
// rotations (Hestenes 1958; Demmel & Veselić, "Jacobi's method is more accurate than QR", SIAM
// J. Matrix Anal. Appl. 13 (1992): small singular values to high relative accuracy): pairs of
// columns are rotated until every pair is orthogonal to rounding, and the column norms are then
// the singular values. Returns the smallest over the largest (0 for a zero matrix).
double jacobi_conditioning(int p, int k, std::vector<double>& b) {
  constexpr double kOrthogonal = 1e-15;  // |a_i·a_j| ≤ this × |a_i| |a_j|: orthogonal to rounding
  constexpr int kMaxSweeps = 60;
  auto col = [&](int j) { return &b[static_cast<size_t>(j) * p]; };
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = false;
    for (int i = 0; i + 1 < k; ++i)
      for (int j = i + 1; j < k; ++j) {
        double* ai = col(i);
        double* aj = col(j);
        double alpha = 0.0, beta = 0.0, gamma = 0.0;
        for (int r = 0; r < p; ++r) alpha += ai[r] * ai[r], beta += aj[r] * aj[r], gamma += ai[r] * aj[r];
        if (!(std::abs(gamma) > kOrthogonal * std::sqrt(alpha * beta))) continue;
        rotated = true;
        const double zeta = (beta - alpha) / (2 * gamma);
        const double t = (zeta >= 0 ? 1.0 : -1.0) / (std::abs(zeta) + std::sqrt(1 + zeta * zeta));
        const double c = 1 / std::sqrt(1 + t * t), sn = c * t;
        for (int r = 0; r < p; ++r) {
          const double x = ai[r], y = aj[r];
          ai[r] = c * x - sn * y;
          aj[r] = sn * x + c * y;
        }
      }
    if (!rotated) break;
  }
  double smallest = INFINITY, largest = 0.0;
  for (int j = 0; j < k; ++j) {
    double n2 = 0.0;
    for (int r = 0; r < p; ++r) n2 += col(j)[r] * col(j)[r];
    smallest = std::min(smallest, std::sqrt(n2));
    largest = std::max(largest, std::sqrt(n2));
  }
  return largest > 0 ? smallest / largest : 0.0;
}

}  // namespace

double calc_conditioning(const Matrix& A) {
  const int m = A.nrow(), n = A.ncol(), k = std::min(m, n), p = std::max(m, n);
  if (k == 0) return 0.0;
  if (k > kMaxJacobiColumns) {
    FactorSVD svd(A);
    Vector sv;
    svd.getSingularValues(sv);
    // Rank deficiency shows as missing or tiny singular values (min(m, n) of them).
    if (sv.size() < k || !(sv[0] > 0)) return 0.0;
    return sv[sv.size() - 1] / sv[0];
  }
  std::vector<double> b(static_cast<size_t>(p) * k);  // A, or Aᵀ when wide: p × k, p ≥ k
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) {
      if (!std::isfinite(A(i, j))) return 0.0;
      b[m >= n ? static_cast<size_t>(j) * p + i : static_cast<size_t>(i) * p + j] = A(i, j);
    }
  const double c = jacobi_conditioning(p, k, b);
  return std::isfinite(c) ? c : 0.0;
}

LeastSquares::LeastSquares(const Matrix& A) : m_(A.nrow()), n_(A.ncol()) {
  if (m_ >= n_ && n_ > 0) {
    qr_.resize(static_cast<size_t>(m_) * n_);
    for (int j = 0; j < n_; ++j)
      for (int i = 0; i < m_; ++i) qr_[static_cast<size_t>(j) * m_ + i] = A(i, j);
    const double ratio = pivoted_qr(m_, n_, qr_, beta_, perm_);
    if (std::isfinite(ratio) && ratio >= kQrMinRatio) return;
  }
  qr_.clear();
  svd_.emplace(A);
}

void LeastSquares::solve(const Vector& b, Vector& x) {
  if (svd_) {
    if (m_ == 0 || n_ == 0) {  // FactorSVD gives an empty x here
      x.resize(n_);
      x = 0.0;
      return;
    }
    svd_->solve(b, x);
    return;
  }
  auto at = [&](int i, int j) { return qr_[static_cast<size_t>(j) * m_ + i]; };
  std::vector<double> y(m_);
  for (int i = 0; i < m_; ++i) y[i] = b[i];
  for (int k = 0; k < n_; ++k) {  // y = Qᵀ b, reflector by reflector
    double d = y[k];
    for (int i = k + 1; i < m_; ++i) d += at(i, k) * y[i];
    d *= beta_[k];
    y[k] -= d;
    for (int i = k + 1; i < m_; ++i) y[i] -= d * at(i, k);
  }
  for (int k = n_ - 1; k >= 0; --k) {  // R z = (Qᵀ b)[0..n), then x = P z
    double s = y[k];
    for (int j = k + 1; j < n_; ++j) s -= at(k, j) * y[j];
    y[k] = s / at(k, k);
  }
  x.resize(n_);
  for (int k = 0; k < n_; ++k) x[perm_[k]] = y[k];
}

}  // namespace rdyn::engine
