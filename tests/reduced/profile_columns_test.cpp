// A new profile shape on the same table: the rebuilt tau column and its refit must equal a
// fresh extraction of the scene with that shape (same grid, same interpolation).
#include "reduced/profile_columns.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "analytic_source.hpp"
#include "models/scene_hash.hpp"
#include "reduced/extract.hpp"

namespace rdyn::reduced {
namespace {

Samples extract_analytic(const models::Scene& scene) {
  test::AnalyticSource src;
  ExtractOptions opt;
  opt.step_rad = 10 * M_PI / 180;
  return extract_samples(src, scene, opt);
}

// The analytic scene with a gated crank-angle profile on the lever.
models::Scene with_shape(double a0, std::vector<double> a, std::vector<double> b) {
  auto scene = test::analytic_scene();
  models::LoadProfile p;
  p.of = "crank";  // the independent coordinate: θ = q
  p.a0 = a0, p.a = std::move(a), p.b = std::move(b);
  scene.joint_torques.push_back({"drive", "lever", 1.5, models::RateGate{"lever", +1}, p});
  return scene;
}

TEST(ProfileColumns, NewShapeOnTheSameTableEqualsAFreshExtraction) {
  const auto base = with_shape(1.0, {}, {});
  const auto shaped = with_shape(0.8, {0.3, -0.1, 0.05}, {0.2, 0.0, -0.07});
  const auto s0 = extract_analytic(base);
  const auto fresh = extract_analytic(shaped);
  const auto rebuilt = with_profile_columns(s0, shaped);
  // The hash now certifies the new shape (it differs from the base scene's).
  ASSERT_TRUE(rebuilt.scene_hash);
  EXPECT_EQ(*rebuilt.scene_hash, *fresh.scene_hash);
  EXPECT_NE(*rebuilt.scene_hash, *s0.scene_hash);
  const int c = rebuilt.column("tau_drive");
  ASSERT_GE(c, 0);
  double max_tau = 0;
  for (size_t i = 0; i < rebuilt.q.size(); ++i) {
    EXPECT_NEAR(rebuilt.columns[c][i], fresh.columns[fresh.column("tau_drive")][i], 1e-12);
    max_tau = std::max(max_tau, std::abs(rebuilt.columns[c][i] - s0.columns[c][i]));
  }
  EXPECT_GT(max_tau, 0.1);  // the shape did change the column

  // Refit into the base model = the model built from the fresh extraction, every coefficient.
  for (auto interp : {Interpolation::Fourier, Interpolation::CubicSpline, Interpolation::Akima}) {
    auto m = make_reduced_model(s0, base, interp);
    refit_profile_columns(m, rebuilt, interp);
    const auto ref = make_reduced_model(fresh, shaped, interp);
    ASSERT_EQ(m.table.coef.size(), ref.table.coef.size());
    for (size_t k = 0; k < m.table.coef.size(); ++k)
      EXPECT_NEAR(m.table.coef[k], ref.table.coef[k], 1e-12 * (1 + std::abs(ref.table.coef[k]))) << k;
    // And the refit tau is the profile between grid points (Fourier: spectral).
    if (interp == Interpolation::Fourier)
      for (double q : {0.05, 1.234, 3.3, 5.9}) {
        const double tau = 0.8 + 0.3 * std::cos(q) - 0.1 * std::cos(2 * q) + 0.05 * std::cos(3 * q) +
                           0.2 * std::sin(q) - 0.07 * std::sin(3 * q);
        EXPECT_NEAR(m.table.eval(m.torques[0].c_tau, q), tau, 1e-10) << q;
      }
    // The equation of motion and the output rows see the new shape too (they read packed copies
    // of the columns, which must follow the refit).
    ReducedWorkspace ws(m), ws_ref(ref);
    init_gates(m, ws);
    init_gates(ref, ws_ref);
    for (double q : {0.05, 1.234, 3.3, 5.9}) {
      double a = 0, p = 0, a_ref = 0, p_ref = 0;
      calc_acceleration(m, ws, q, 2.0, a, p);
      calc_acceleration(ref, ws_ref, q, 2.0, a_ref, p_ref);
      EXPECT_NEAR(a, a_ref, 1e-11 * (1 + std::abs(a_ref))) << q;
      EXPECT_NEAR(p, p_ref, 1e-11 * (1 + std::abs(p_ref))) << q;
      std::vector<double> f(m.force_names.size() + 1), f_ref(f.size());
      EXPECT_NEAR(calc_sample(m, ws, q, 2.0, a, p, f.data()), calc_sample(ref, ws_ref, q, 2.0, a_ref, p_ref, f_ref.data()),
                  1e-11);
      EXPECT_NEAR(p, p_ref, 1e-11 * (1 + std::abs(p_ref))) << q;
    }
  }
}

TEST(ProfileColumns, AnotherJointsAngleNeedsItsPositionColumn) {
  auto scene = with_shape(1.0, {}, {});
  scene.joint_torques[0].profile->of = "lever";
  const auto s = extract_analytic(with_shape(1.0, {}, {}));
  EXPECT_THROW(calc_profile_angles(s, scene, "lever"), TableError);
  // With p_/k_ columns: θ = p + k·q.
  Samples t = s;
  t.add("p_lever", std::vector<double>(s.q.size(), 0.25));
  t.add("k_lever", std::vector<double>(s.q.size(), 1.0));
  const auto th = calc_profile_angles(t, scene, "lever");
  for (size_t i = 0; i < s.q.size(); ++i) EXPECT_DOUBLE_EQ(th[i], 0.25 + s.q[i]);
  EXPECT_EQ(calc_profile_angles(s, scene, "crank"), s.q);
}

TEST(ProfileColumns, MissingTauColumnIsRefused) {
  const auto s = extract_analytic(test::analytic_scene());  // no profiled load: no tau column
  EXPECT_THROW(with_profile_columns(s, with_shape(1.0, {}, {})), TableError);
}

}  // namespace
}  // namespace rdyn::reduced
