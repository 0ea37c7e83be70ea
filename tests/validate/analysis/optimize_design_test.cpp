// The design of `rdyn optimize` (validate/analysis/optimize_design.cpp): the parameter vector's
// layout, a shifted series against its closed form, the shaped scene's profiles, and refusals.
#include "validate/analysis/optimize_design.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

TEST(OptimizeDesign, AShiftedSeriesIsTheSeriesAtTheShiftedAngle) {
  // τ(θ − s) through the angle-difference identities, against τ evaluated at θ − s.
  const Series s{0.7, {0.3, -0.2, 0.05}, {0.4, 0.1, -0.15}};
  for (double shift : {0.0, 0.4, -1.3, M_PI})
    for (double th : {0.0, 0.5, 2.0, 5.9}) {
      EXPECT_NEAR(eval_series(shifted(s, shift), th), eval_series(s, th - shift), 1e-14) << shift << " " << th;
    }
  // The minimum over a turn does not move with a shift.
  EXPECT_NEAR(series_minimum(shifted(s, 1.1)), series_minimum(s), 1e-12);
}

TEST(OptimizeDesign, TheBicyclesTwoHipsShareOneShapeHalfATurnApartAndTheVectorIsLaidOutByGroup) {
  // The bicycle's optimize block: the right hip its own shape, the left the same shifted by 180°.
  const auto scene = models::load_scene("bicycle");
  ASSERT_TRUE(scene.optimize.has_value());
  OptimizeOptions opt;
  opt.harmonics = 2;
  const Design d = resolve_design(scene, *scene.optimize, opt);
  ASSERT_EQ(d.loads.size(), scene.joint_torques.size());
  ASSERT_EQ(d.groups.size(), 1u);               // one shape, shared
  EXPECT_TRUE(d.groups[0].fixed_a0);            // a0 ≡ 1: the calibrated amplitude carries the scale
  EXPECT_EQ(d.n, 2 * d.H);                      // a_1..a_H, b_1..b_H
  EXPECT_NEAR(std::abs(d.loads[1].shift - d.loads[0].shift), M_PI, 1e-12);
  // x = (a1, a2, b1, b2): the shaped scene profiles each hip with the shifted series.
  const std::vector<double> x{0.2, -0.1, 0.3, 0.05};
  const auto shaped = shaped_scene(scene, d, x.data());
  for (const auto& dl : d.loads) {
    const auto& p = shaped.joint_torques[dl.torque].profile;
    ASSERT_TRUE(p.has_value());
    const Series got{p->a0, p->a, p->b};
    const Series want = shifted(group_series(d, dl.group, x.data()), dl.shift);
    for (double th : {0.0, 1.0, 3.0}) EXPECT_NEAR(eval_series(got, th), eval_series(want, th), 1e-15);
    EXPECT_NEAR(eval_series(got, 0.3 + dl.shift), 1.0 + 0.2 * std::cos(0.3) - 0.1 * std::cos(0.6) +
                                                     0.3 * std::sin(0.3) + 0.05 * std::sin(0.6),
                1e-14);
  }
}

TEST(OptimizeDesign, ATorqueLeftOutOfTheDesignIsRefusedNamingTheBlock) {
  auto scene = models::load_scene("bicycle");
  models::OptimizeSpec spec = *scene.optimize;
  spec.loads.resize(1);  // only the first hip listed: the other cannot be calibrated with it
  try {
    resolve_design(scene, spec, OptimizeOptions{});
    ADD_FAILURE() << "accepted";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "optimize.loads");
    EXPECT_NE(std::string(e.what()).find("is not a design load"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rdyn::validate
