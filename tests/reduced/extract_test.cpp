// Extraction on an analytic mechanism: every method recovers the known parameters.
#include "reduced/extract.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "analytic_source.hpp"

namespace rdyn::reduced {
namespace {

TEST(Extract, KinetostaticRecoversClosedFormSliderCrankInertia) {
  test::AnalyticSource src;
  src.k = 2.0;
  const auto scene = test::analytic_scene();
  ExtractOptions opt;
  opt.step_rad = 10 * M_PI / 180;
  const Samples s = extract_samples(src, scene, opt);
  ASSERT_EQ(s.q.size(), 36u);
  for (size_t i = 0; i < s.q.size(); ++i) {
    const double q = s.q[i];
    EXPECT_NEAR(s.columns[s.require("m1")][i], src.sc.m1(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("m2")][i], src.sc.m2(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("me1_F")][i], test::AnalyticSource::me1(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("me2_F")][i], test::AnalyticSource::me2(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("Q_cons")][i], -2.0 * std::sin(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("Qx_cons_F")][i], 0.4 * std::cos(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("r_lever")][i], std::cos(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("rx_F_lever")][i], 0.5, 1e-14);
  }
}

TEST(Extract, IntegratedM1ConvergesWithTheGrid) {
  // m1 = m1(q_first) + ∫ 2 m2 dq with a periodic spline of m2: error falls with the grid.
  test::AnalyticSource src;
  const auto scene = test::analytic_scene();
  double previous = INFINITY;
  for (double deg : {30.0, 10.0, 5.0}) {
    ExtractOptions opt;
    opt.step_rad = deg * M_PI / 180;
    opt.method = Method::Integrated;
    const Samples s = extract_samples(src, scene, opt);
    double err = 0, scale = 0;
    for (size_t i = 0; i < s.q.size(); ++i) {
      err = std::max(err, std::abs(s.columns[0][i] - src.sc.m1(s.q[i])));
      scale = std::max(scale, std::abs(src.sc.m1(s.q[i])));
    }
    EXPECT_LT(err, previous / 4) << deg;
    if (deg == 10.0) {
      EXPECT_LT(err / scale, 1e-3);
    }
    previous = err;
  }
}

TEST(Extract, SwitchAnglesAreExactRootsOfTheRatio) {
  test::AnalyticSource src;
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 1.0, models::RateGate{"lever", +1}});
  ExtractOptions opt;
  opt.step_rad = 40 * M_PI / 180;  // 90° and 270° fall between grid points
  const Samples s = extract_samples(src, scene, opt);
  const auto* roots = s.roots_of("r_lever");
  ASSERT_NE(roots, nullptr);
  ASSERT_EQ(roots->size(), 2u);  // cos q = 0
  EXPECT_NEAR((*roots)[0], M_PI / 2, 1e-12);
  EXPECT_NEAR((*roots)[1], 3 * M_PI / 2, 1e-12);
}

TEST(Extract, GridMustDivideATurn) {
  test::AnalyticSource src;
  ExtractOptions opt;
  opt.step_rad = 7 * M_PI / 180;
  EXPECT_THROW(extract_samples(src, test::analytic_scene(), opt), TableError);
}

}  // namespace
}  // namespace rdyn::reduced
