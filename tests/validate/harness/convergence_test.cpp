#include "validate/harness/convergence.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/validate/harness/run_records.hpp"

namespace rdyn::validate {
namespace {

using test::record;

TEST(Convergence, ObservedOrderOfAPowerLaw) {
  // e = 3·h⁴ (a cubic spline), plus points on a floor of 1e-9 that must not bend the fit.
  std::vector<std::pair<double, double>> pts;
  for (double h : {30.0, 20.0, 10.0, 5.0}) pts.push_back({h, 3e-8 * std::pow(h, 4)});
  for (double h : {1.0, 0.5}) pts.push_back({h, 1e-9});
  EXPECT_NEAR(calc_observed_order(pts, 1e-8), 4.0, 1e-12);
  EXPECT_GT(std::abs(calc_observed_order(pts, 0.0) - 4.0),
            0.3);  // kept, the floor points bend the fit
  EXPECT_TRUE(std::isnan(calc_observed_order({{10, 1e-3}}, 0.0)));
  EXPECT_TRUE(
      std::isnan(calc_observed_order({{10, 1e-3}, {10, 2e-3}}, 0.0)));  // one grid: no slope
}

TEST(Convergence, SeriesPerInterpolationAtTheTightTolerance) {
  std::vector<RunRecord> runs;
  for (double h : {30.0, 10.0, 5.0})
    for (const char* interp : {"cubic", "fourier"}) {
      auto r = record(
          "reduced", 1e-3,
          {{"F", std::string(interp) == "cubic" ? 1e-6 * std::pow(h, 4) : 1e-3 * std::pow(h, 2)}});
      r.grid_deg = h;
      r.interpolation = interp;
      r.tolerance = 1e-10;
      runs.push_back(r);
    }
  auto loose = runs[0];
  loose.tolerance = 1e-6;  // not at the tight tolerance: left out
  loose.errors.signals[0].max_rel = 1.0;
  runs.push_back(loose);
  const auto s = calc_convergence(runs, "F", 1e-10, 0.0);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].interpolation, "cubic");
  ASSERT_EQ(s[0].points.size(), 3u);
  EXPECT_EQ(s[0].points.front().first, 30.0);  // coarse to fine
  EXPECT_NEAR(s[0].order, 4.0, 1e-9);
  EXPECT_NEAR(s[1].order, 2.0, 1e-9);
}

}  // namespace
}  // namespace rdyn::validate
