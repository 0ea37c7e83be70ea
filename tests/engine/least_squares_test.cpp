// LeastSquares (engine/least_squares.cpp): its pivoted QR gives SimTK::FactorSVD::solve's
// least-squares answers (gelss, an SVD per call) to rounding on tall and square matrices away from
// rank loss, redundant rows included, and satisfies the normal equations; near or at rank loss and
// for wide matrices it hands over to FactorSVD, keeping the minimum-norm answers there.
#include "engine/least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace rdyn::engine {
namespace {

using SimTK::Matrix;
using SimTK::Vector;

Matrix random_matrix(int m, int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix A(m, n);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng);
  return A;
}

Vector random_vector(int m, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Vector b(m);
  for (int i = 0; i < m; ++i) b[i] = u(rng);
  return b;
}

double max_abs(const Vector& v) {
  double w = 0.0;
  for (int i = 0; i < v.size(); ++i) w = std::max(w, std::abs(v[i]));
  return w;
}

// Both routes on A for a few right-hand sides: equal to 1e-12 of the solution's size.
void expect_as_factor_svd(const Matrix& A, std::mt19937& rng) {
  LeastSquares ls(A);
  SimTK::FactorSVD svd(A);
  for (int k = 0; k < 4; ++k) {
    const Vector b = random_vector(A.nrow(), rng);
    Vector x, ref;
    ls.solve(b, x);
    svd.solve(b, ref);
    ASSERT_EQ(x.size(), A.ncol());
    EXPECT_LE(max_abs(x - ref), 1e-12 * std::max(1.0, max_abs(ref))) << A.nrow() << "×" << A.ncol();
    // Normal equations Aᵀ(A x − b) = 0: x is a least-squares solution.
    const Vector g = ~A * (A * x - b);
    EXPECT_LE(max_abs(g), 1e-12 * std::max(1.0, max_abs(b)));
  }
}

TEST(LeastSquares, QrAgreesWithFactorSvdOnTallSquareAndLoopJacobianShapes) {
  std::mt19937 rng(7);
  for (auto [m, n] : {std::pair{8, 7}, std::pair{5, 5}, std::pair{12, 4}, std::pair{1, 1}}) {
    const Matrix A = random_matrix(m, n, rng);
    EXPECT_TRUE(LeastSquares(A).by_qr()) << m << "×" << n;
    expect_as_factor_svd(A, rng);
  }
}

TEST(LeastSquares, RedundantRowsKeepTheQrAndItsAnswer) {
  // Two loops imposing the same condition: rows repeat, the columns keep full rank (one solution).
  std::mt19937 rng(5);
  Matrix A = random_matrix(8, 6, rng);
  for (int j = 0; j < 6; ++j) A(7, j) = A(2, j), A(6, j) = -0.5 * A(4, j);
  EXPECT_TRUE(LeastSquares(A).by_qr());
  expect_as_factor_svd(A, rng);
}

TEST(LeastSquares, RankLossAndNearRankLossGoToTheSvdWithItsMinimumNorm) {
  std::mt19937 rng(11);
  Matrix A = random_matrix(6, 5, rng);
  for (int i = 0; i < 6; ++i) A(i, 4) = 0.0;  // a mobility no constraint touches
  LeastSquares ls(A);
  EXPECT_FALSE(ls.by_qr());
  Vector x;
  const Vector b = random_vector(6, rng);
  ls.solve(b, x);
  EXPECT_EQ(x[4], 0.0);  // minimum norm: the untouched mobility's entry is zero, not arbitrary
  EXPECT_LE(max_abs(~A * (A * x - b)), 1e-12);
  // Conditioning 1e-5 (a singular configuration's neighbourhood): the SVD; 0.05: the QR.
  for (double c : {1e-5, 0.05}) {
    Matrix D(4, 3, 0.0);
    D(0, 0) = 1.0, D(1, 1) = 0.7, D(2, 2) = c, D(3, 0) = 0.2;
    EXPECT_EQ(LeastSquares(D).by_qr(), c > LeastSquares::kQrMinRatio) << c;
    expect_as_factor_svd(D, rng);
  }
}
TEST(LeastSquares, AnUnderdeterminedSystemGetsTheClosedFormMinimumNorm) {
  std::mt19937 rng(3);
  const Matrix A = random_matrix(3, 6, rng);
  const Vector b = random_vector(3, rng);
  Vector x;
  LeastSquares ls(A);
  EXPECT_FALSE(ls.by_qr());
  ls.solve(b, x);
  // x = Aᵀ (A Aᵀ)⁻¹ b, by Simbody's LU of the 3 × 3 Gram matrix.
  const Matrix gram = A * ~A;
  SimTK::FactorLU lu(gram);
  Vector y;
  lu.solve(b, y);
  const Vector ref = ~A * y;
  EXPECT_LE(max_abs(x - ref), 1e-12 * max_abs(ref));
  EXPECT_LE(max_abs(A * x - b), 1e-13);
}

TEST(LeastSquares, AnEmptyMatrixGivesZeros) {
  Vector x;
  LeastSquares(Matrix(0, 3)).solve(Vector(0), x);
  ASSERT_EQ(x.size(), 3);
  EXPECT_EQ(max_abs(x), 0.0);
  LeastSquares(Matrix(4, 3, 0.0)).solve(Vector(4, 1.0), x);  // nothing constrains x: zero
  EXPECT_EQ(max_abs(x), 0.0);
}

}  // namespace
}  // namespace rdyn::engine
