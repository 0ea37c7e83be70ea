// Least-squares solves of one small matrix (a loop Jacobian) for many right-hand sides.
// Internal to engine/ (includes Simbody).
#pragma once

#include <Simbody.h>

#include <optional>
#include <vector>

namespace rdyn::engine {

// The least-squares solution x of A x = b that SimTK::FactorSVD::solve gives (LAPACK gelss: the
// minimum-norm one, singular values ≤ max(m, n)·ε^(7/8)·s_0 cut), for every right-hand side from
// one factorization. FactorSVD::solve recomputes an SVD on every call (Simbody 3.7, FactorSVD.cpp:
// doSolve copies the matrix and calls gelss): the branch rates' 4 solves and the chord Newton
// projection's 3–4 per Jacobian were ~10 % of a sweep case's instructions (issue #28).
// A tall or square A whose column-pivoted Householder QR is well away from rank loss
// (|R_nn| ≥ kQrMinRatio |R_11|; the loop Jacobians of regular mechanisms: the bicycle's
// conditioning is 0.06) has one least-squares solution, which the QR gives to rounding
// (Golub & Van Loan, Matrix Computations, §5.3: x = P R⁻¹ Qᵀ b). Any other A — wide, near or at
// rank loss, where the minimum-norm choice and the rank cut matter (singular configurations) —
// goes to FactorSVD::solve itself, as before.
class LeastSquares {
 public:
  static constexpr double kQrMinRatio = 1e-3;
  explicit LeastSquares(const SimTK::Matrix& A);
  // b: A.nrow() entries; x is resized to A.ncol().
  // Not const: the SVD fallback's solve is not (Simbody 3.7).
  void solve(const SimTK::Vector& b, SimTK::Vector& x);
  bool by_qr() const { return !svd_; }

 private:
  int m_ = 0, n_ = 0;
  std::vector<double> qr_;    // column-major m × n: R above the diagonal, Householder vectors below
  std::vector<double> beta_;  // reflector k: I − beta_k v_k v_kᵀ, v_k = (1, qr_[k+1.., k])
  std::vector<int> perm_;     // column k of R is column perm_[k] of A
  std::optional<SimTK::FactorSVD> svd_;  // the fallback
};

// Smallest over largest singular value of A (0 when A is empty, zero, not finite or of
// missing rank): the loop Jacobian's conditioning, which decides singular configurations
// (kSingularConditioning) and where projections are polished. For min(m, n) ≤
// kMaxJacobiColumns by one-sided Jacobi rotations, ~3 k instructions for the bicycle's 4 × 4
// where SimTK::FactorSVD (LAPACK gesdd with Simbody's set-up) took ~18 k: 0.9 M of a ~30 M
// sweep case (issue #28). Larger ones (a 40-loop chain's 80 rows) go to FactorSVD. The two
// agree to rounding (tests/engine/least_squares_test.cpp).
inline constexpr int kMaxJacobiColumns = 12;
double calc_conditioning(const SimTK::Matrix& A);

}  // namespace rdyn::engine
