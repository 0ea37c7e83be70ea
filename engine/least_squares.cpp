#include "engine/least_squares.hpp"

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

}  // namespace

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
