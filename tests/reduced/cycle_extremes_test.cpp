// Maxima over a periodic cycle split into smooth pieces (reduced/cycle_extremes.hpp), on
// functions whose maxima are known in closed form: an interior maximum between samples, one at a
// piece's end (a jump, as a load switch makes), and one just across the period's wrap.
#include "reduced/cycle_extremes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace rdyn::reduced {
namespace {

constexpr double kTwoPi = 2 * M_PI;

TEST(CycleExtremes, SampleThetaEndsExactlyAtTheEnd) {
  EXPECT_EQ(sample_theta(0.1, 0.7, 3, 3), 0.7);
  EXPECT_DOUBLE_EQ(sample_theta(0.0, 1.0, 1, 4), 0.25);
}

TEST(CycleExtremes, GoldenSectionFindsAnInteriorMaximumAndKeepsAnEndOfAMonotonePiece) {
  double x = 0, v = -INFINITY;
  auto bump = [](double t) { return 1.0 - (t - 0.37) * (t - 0.37); };
  golden_max(bump, 0.0, 1.0, bump(0.0), bump(1.0), 1e-12, x, v);
  EXPECT_NEAR(x, 0.37, 1e-6);  // the bracket is 1e-12; the location of a flat maximum √ulp
  EXPECT_NEAR(v, 1.0, 1e-14);
  double x2 = 0, v2 = -INFINITY;
  auto rising = [](double t) { return t; };
  golden_max(rising, 0.0, 2.0, 0.0, 2.0, 1e-12, x2, v2);
  EXPECT_EQ(x2, 2.0);
  EXPECT_EQ(v2, 2.0);
}

// Brent's method against the closed form and against golden section (the other route) on the
// same bracket: the same maximum to rounding, its place within the bracket's width, in half
// golden section's evaluations or fewer.
TEST(CycleExtremes, BrentFindsTheMaximumGoldenSectionFindsInFewerEvaluations) {
  for (const double c : {0.37, 0.5, 0.61, 0.999}) {
    int brent_evals = 0, golden_evals = 0;
    auto bump = [c](double t) { return 2.0 + std::cos(3 * (t - c)) + 0.1 * std::sin(t); };
    auto brent_f = [&](double t) { return ++brent_evals, bump(t); };
    auto golden_f = [&](double t) { return ++golden_evals, bump(t); };
    double xb = 0, vb = -INFINITY, xg = 0, vg = -INFINITY;
    const double lo = c - 0.4, hi = c + 0.3, x0 = c - 0.05;  // x0 above both ends: a bracket
    brent_max(brent_f, lo, hi, x0, bump(x0), 1e-10, xb, vb);
    golden_max(golden_f, lo, hi, bump(lo), bump(hi), 1e-10, xg, vg);
    // The maximum of cos(3(t − c)) + 0.1 sin t: 3 sin(3(t − c)) = 0.1 cos t, t ≈ c + cos(c)/90.
    double t = c;
    for (int it = 0; it < 50; ++it) t -= (-3 * std::sin(3 * (t - c)) + 0.1 * std::cos(t)) /
                                         (-9 * std::cos(3 * (t - c)) - 0.1 * std::sin(t));
    EXPECT_NEAR(vb, bump(t), 2e-15) << c;
    EXPECT_NEAR(vb, vg, 2e-15) << c;
    EXPECT_NEAR(xb, t, 1e-7) << c;  // a flat maximum: its place to √(rounding)
    EXPECT_LE(2 * brent_evals, golden_evals) << c << ": " << brent_evals << " against " << golden_evals;
  }
}

TEST(CycleExtremes, ThreeQuantitiesOverTwoPiecesMatchTheirClosedForms) {
  // Pieces [0, 3] and [3, 2π]; 12 samples per period (every maximum lies between samples).
  // q0 = cos(θ − 1.234): max 1 at 1.234. q1 = θ on the first piece, θ − 4 on the second: a jump
  // at the piece boundary, max 3 at θ = 3 (the first piece's end; the second rises to 2π − 4). q2 = cos(θ − 0.05) over the
  // cycle: max 1 at 0.05, refined from the sample θ = 0 towards the next (and the previous one
  // across the wrap, 2π − π/6).
  const std::vector<double> a{0.0, 3.0}, b{3.0, kTwoPi};
  auto eval = [](int piece, double th, double* out) {
    out[0] = std::cos(th - 1.234);
    out[1] = piece == 0 ? th : th - 4.0;
    out[2] = std::cos(th - 0.05);
  };
  std::vector<double> value, where;
  find_extremes(a, b, 12, kTwoPi, 3, eval, value, where);
  ASSERT_EQ(value.size(), 3u);
  EXPECT_NEAR(value[0], 1.0, 1e-14);
  EXPECT_NEAR(where[0], 1.234, 1e-6);
  EXPECT_EQ(value[1], 3.0);
  EXPECT_EQ(where[1], 3.0);
  EXPECT_NEAR(value[2], 1.0, 1e-14);
  EXPECT_NEAR(where[2], 0.05, 1e-6);
}

TEST(CycleExtremes, AMaximumJustBeforeTheWrapIsRefinedInThePreviousPiece) {
  // One piece [0, 2π), max of cos(θ + 0.05) at 2π − 0.05: the best sample is θ = 0 (= 2π), the
  // refinement looks on the last sub-interval of the piece before it (the same piece, wrapped).
  auto eval = [](int, double th, double* out) { out[0] = std::cos(th + 0.05); };
  std::vector<double> value, where;
  find_extremes(std::vector<double>{0.0}, std::vector<double>{kTwoPi}, 12, kTwoPi, 1, eval, value, where);
  EXPECT_NEAR(value[0], 1.0, 1e-14);
  EXPECT_NEAR(std::remainder(where[0] + 0.05, kTwoPi), 0.0, 1e-6);
}

TEST(CycleExtremes, AnApproximateScanPicksTheSampleAndEveryValueComesFromEval) {
  // The scan is off by up to 1e-6 (the steady cycle's Hermite scan: ~1e-8): the same maxima as
  // the exact scan, to the refinement's own accuracy, and each value is eval's at its `where`.
  const std::vector<double> a{0.0, 3.0}, b{3.0, kTwoPi};
  auto eval = [](int piece, double th, double* out) {
    out[0] = std::cos(th - 1.234);
    out[1] = piece == 0 ? th : th - 4.0;
  };
  int scans = 0, evals = 0;
  auto scan = [&](int piece, double th, double* out) {
    ++scans;
    eval(piece, th, out);
    out[0] += 1e-6 * std::sin(37 * th), out[1] += 1e-6 * std::cos(41 * th);
  };
  auto counted = [&](int piece, double th, double* out) { ++evals, eval(piece, th, out); };
  std::vector<double> value, where, exact_value, exact_where;
  find_extremes(a, b, 12, kTwoPi, 2, scan, counted, value, where);
  find_extremes(a, b, 12, kTwoPi, 2, eval, exact_value, exact_where);
  EXPECT_EQ(scans, 15);  // ≥ 12 per period: 6 + 1 points on [0, 3], 7 + 1 on [3, 2π]
  EXPECT_LT(evals, 2 * (1 + 2 * 70));  // the refinement alone: the best sample and golden on two sides
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(value[k], exact_value[k], 1e-14) << k;
    double at[2];
    eval(0, where[k], at);  // both maxima lie on the first piece (1.234 and its end 3)
    EXPECT_NEAR(value[k], at[k], 1e-14) << k;  // no scan offset (1e-6) left in a value
  }
  EXPECT_EQ(value[1], 3.0);
}

}  // namespace
}  // namespace rdyn::reduced
