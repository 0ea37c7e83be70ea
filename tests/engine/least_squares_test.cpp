// LeastSquares (engine/least_squares.cpp): its pivoted QR gives SimTK::FactorSVD::solve's
// least-squares answers (gelss, an SVD per call) to rounding on tall and square matrices away from
// rank loss, redundant rows included, and satisfies the normal equations; near or at rank loss and
// for wide matrices it hands over to FactorSVD, keeping the minimum-norm answers there.
// calc_conditioning (one-sided Jacobi) against FactorSVD's singular values on random matrices of
// every shape and on the loop Jacobians of several mechanisms along their turn.
#include "engine/least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "engine/branch_rates.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"
#include "test_scenes.hpp"

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

// FactorSVD's smallest over largest singular value: the route calc_conditioning replaced.
double svd_conditioning(const Matrix& A) {
  SimTK::FactorSVD svd(A);
  Vector sv;
  svd.getSingularValues(sv);
  return sv[sv.size() - 1] / sv[0];
}

// Jacobi's and LAPACK's smallest singular values agree to rounding relative to the largest one
// (gesdd's error bound, ε σ_max: relative to the smallest it grows as 1/κ).
void expect_conditioning_as_svd(const Matrix& A, const std::string& what) {
  const double ref = svd_conditioning(A), c = calc_conditioning(A);
  EXPECT_NEAR(c, ref, 1e-13 + 1e-12 * ref) << what;
}

TEST(Conditioning, AsFactorSvdOnEveryShape) {
  std::mt19937 rng(28);
  const int shapes[][2] = {{1, 1}, {1, 3}, {3, 1}, {2, 2}, {4, 4}, {6, 4}, {4, 6}, {3, 5}, {8, 7}, {12, 12}, {20, 12}, {14, 13}};
  for (const auto& sh : shapes)
    for (int trial = 0; trial < 5; ++trial)
      expect_conditioning_as_svd(random_matrix(sh[0], sh[1], rng), std::to_string(sh[0]) + "x" + std::to_string(sh[1]));
  // Graded columns: conditioning 1e-2 … 1e-8.
  for (double scale : {1e-2, 1e-5, 1e-8}) {
    Matrix A = random_matrix(5, 4, rng);
    for (int i = 0; i < 5; ++i) A(i, 3) = A(i, 0) + scale * A(i, 3);
    expect_conditioning_as_svd(A, "graded " + std::to_string(scale));
    EXPECT_LT(calc_conditioning(A), 10 * scale);
  }
}

TEST(Conditioning, RankLossZeroEmptyAndNotFinite) {
  std::mt19937 rng(7);
  Matrix A = random_matrix(4, 4, rng);
  for (int i = 0; i < 4; ++i) A(i, 2) = 2 * A(i, 1);  // rank 3
  EXPECT_LT(calc_conditioning(A), 1e-15);
  Matrix Z(3, 3);
  Z = 0.0;
  EXPECT_EQ(calc_conditioning(Z), 0.0);
  EXPECT_EQ(calc_conditioning(Matrix(0, 4)), 0.0);
  Matrix N = random_matrix(3, 3, rng);
  N(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(calc_conditioning(N), 0.0);
  Matrix I(3, 3);
  I = 0.0;
  for (int i = 0; i < 3; ++i) I(i, i) = 2.0;
  EXPECT_EQ(calc_conditioning(I), 1.0);
}

// The loop Jacobians (G restricted to the free mobilities) of the four-bar, the bicycle with its
// constraint actuators, the slider-crank and a parallelogram near its aligned position, at
// configurations along the turn: both routes agree, and the parallelogram's falls towards 0.
TEST(Conditioning, AsFactorSvdOnLoopJacobiansOfMechanisms) {
  const std::vector<models::Scene> scenes{models::load_scene("fourbar"), models::load_scene("bicycle"),
                                          models::load_scene("slider-crank"),
                                          models::parse_scene(test::parallelogram_yaml(0.0, true), "p.yaml")};
  for (const auto& scene : scenes) {
    const FullModel model(scene);
    FullWorkspace ws(model);
    const auto& m = model.impl();
    for (int i = 1; i < 8; ++i) {
      const double q = scene.initial.q + 0.05 + 2 * M_PI * i / 8.0;
      calc_kinetostatic(model, ws, q, 0.0, 0.0, Loads::Off);
      const SimTK::State& s = ws.impl().state;
      m.system.realize(s, SimTK::Stage::Position);
      const auto J = calc_split_jacobian(m, s);
      ASSERT_GT(J.G_free.nrow(), 0) << scene.source_file;
      expect_conditioning_as_svd(J.G_free, scene.source_file + " at q = " + std::to_string(q));
      EXPECT_EQ(calc_loop_conditioning(model, ws), calc_conditioning(J.G_free)) << scene.source_file;
    }
  }
}

}  // namespace
}  // namespace rdyn::engine
