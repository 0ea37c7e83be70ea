// Refinements of the grid visit against closed forms on the analytic source (a slider-crank with
// a lever whose ratio is cos q: zero at ±90°): the switch angle by Brent and by Newton, the
// quadratic estimate, and the singular-sample limit, whose O(δ⁴) truncation a wrong weight
// would turn into O(δ²).
#include "reduced/sweep_refine.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "analytic_source.hpp"

namespace rdyn::reduced {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The analytic source with the ratios' slopes (the Simbody source gives them from b = dr/dq).
struct SourceWithSlopes : test::AnalyticSource {
  std::optional<std::pair<double, double>> ratio_and_slope(double q, int joint) override {
    ++calls;
    return joint == 0 ? std::make_pair(1.0, 0.0) : std::make_pair(std::cos(q), -std::sin(q));
  }
};

TEST(SweepRefine, QuadraticZeroIsExactOnAQuadraticAndFallsBackToTheChord) {
  auto y = [](double x) { return (x - 0.3) * (x + 2.0); };
  EXPECT_NEAR(quadratic_zero(0.0, y(0.0), 0.2, y(0.2), 0.5, y(0.5)), 0.3, 1e-14);
  // A straight line: no curvature, the chord's zero (exact too).
  auto l = [](double x) { return 2 * x - 0.7; };
  EXPECT_NEAR(quadratic_zero(0.0, l(0.0), 0.2, l(0.2), 0.5, l(0.5)), 0.35, 1e-14);
}

TEST(SweepRefine, TheLeversSwitchAngleByBrentAndByNewton) {
  SourceWithSlopes src;
  const int lever = 1;
  // The grid interval [80°, 100°] around the zero of cos q, and [260°, 280°] for the other.
  for (const double centre : {kPi / 2, 3 * kPi / 2}) {
    const double a = centre - 0.17, b = centre + 0.2;
    const double ra = std::cos(a), rb = std::cos(b);
    const double est = a - ra * (b - a) / (rb - ra);  // the chord's zero, off by ~1e-3
    EXPECT_NEAR(refine_root(src, lever, a, ra, b, rb, est), centre, 1e-12);
    const auto n = newton_root(src, lever, a, ra, -std::sin(a), b, rb, -std::sin(b));
    ASSERT_TRUE(n.has_value());
    EXPECT_NEAR(*n, centre, 1e-13);
    // Without slopes there is no Newton: the caller falls back to Brent.
    test::AnalyticSource plain;
    EXPECT_FALSE(newton_root(plain, lever, a, ra, -std::sin(a), b, rb, -std::sin(b)).has_value());
  }
  // A zero on a grid point is that grid point.
  EXPECT_EQ(refine_root(src, lever, kPi / 2, 0.0, 2.0, std::cos(2.0), 1.8), kPi / 2);
}

TEST(SweepRefine, TheSingularLimitIsTheSampleToFourthOrder) {
  // At a regular point the limit from both sides must give the sample itself: m1 of the
  // slider-crank varies by ~50 % a turn, so a combination with the wrong weights (e.g. the plain
  // mean of the four sides, O(δ²) = 1e-4 × m1'') would miss by ~1e-5 of m1; Richardson's by ~1e-9.
  test::AnalyticSource src;
  for (const double q : {0.3, 1.2, 2.9}) {
    GridSample g = src.sample(q, true);
    const GridSample exact = g;
    ASSERT_TRUE(calc_singular_limit(src, q, 10 * kPi / 180, true, g));
    const double m1 = exact.acceleration.driving_force;
    EXPECT_NEAR(g.acceleration.driving_force, m1, 1e-8 * m1) << q;
    EXPECT_NEAR(g.velocity.driving_force, exact.velocity.driving_force, 1e-8 * m1) << q;
    EXPECT_NEAR(g.ratios.wrt_q[1], std::cos(q), 1e-9) << q;
    EXPECT_NEAR(g.conservative.forces.constraint_forces[0], exact.conservative.forces.constraint_forces[0], 1e-9) << q;
  }
}

// The pole test against closed forms: a simple pole a/x plus a regular part is found whatever
// the regular part; regular columns (odd, even, steep, or zero up to rounding noise) are not.
TEST(SweepRefine, ASimplePoleIsToldFromRegularColumns) {
  const double d = 0.0025;
  auto sides = [d](auto f) { return std::array<double, 4>{f(-d), f(-d / 2), f(d / 2), f(d)}; };
  auto pole = [](const std::array<double, 4>& v) { return is_simple_pole(v[0], v[1], v[2], v[3]); };
  // The isosceles slider-crank's me1 near its folded configuration: 0.0264/x + 1.9 + 3 x.
  EXPECT_TRUE(pole(sides([](double x) { return 0.0264 / x + 1.9 + 3 * x; })));
  EXPECT_TRUE(pole(sides([](double x) { return -1e-4 / x + 50 * x * x; })));  // small residue, curved rest
  EXPECT_FALSE(pole(sides([](double x) { return 1.9 + 3 * x; })));            // a regular slope
  EXPECT_FALSE(pole(sides([](double x) { return 1e4 * std::sin(40 * x); }))); // steep but regular
  EXPECT_FALSE(pole(sides([](double x) { return 2 + x * x; })));              // even
  EXPECT_FALSE(pole(sides([](double x) { return 1 / (x * x); })));            // even pole: not simple (a dead point's kind)
  // Rounding noise whose antisymmetric part happens to double with a flipped sign (noise of the
  // pole's own shape passes here: the extraction checks the residue against the grid).
  EXPECT_FALSE(is_simple_pole(1e-13, -2e-13, 2.1e-13, -0.9e-13));
}

}  // namespace
}  // namespace rdyn::reduced
