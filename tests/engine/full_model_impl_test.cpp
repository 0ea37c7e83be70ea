// The Simbody objects behind FullModel (engine/full_model_impl.hpp): a gear-folded joint's
// coordinate and rate (Impl::joint_q, joint_u, body_rate) against the same joint simulated as
// its own body with a gear constraint (fold_geared_bodies false) at the same configuration, and
// the mobility count (calc_mobility_count) of a four-bar and of the bicycle folded and unfolded.
#include "engine/full_model_impl.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/kinetostatic.hpp"
#include "models/gear_fold.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::engine {
namespace {

FullModelOptions unfolded() {
  FullModelOptions o;
  o.fold_geared_bodies = false;
  return o;
}

// The bicycle's flywheel turns at 3 × the crank (models/scenes/bicycle.yaml): folded into the
// crank it has no Simbody body, its coordinate is r·q_crank + c; unfolded, Simbody's gear
// constraint puts it there. Both at the same crank angle and rate must agree.
TEST(FullModelImpl, FoldedJointFollowsItsDriverAsTheUnfoldedGearDoes) {
  models::Scene scene = models::load_scene("bicycle");
  const int crank = scene.joint_index("crank"), fly = scene.joint_index("flywheel");
  ASSERT_GE(fly, 0);
  // The flywheel's guess fixes the gear's offset c (calc_gear_offset): 0.7 rad, so that a fold
  // that dropped c would differ from the unfolded gear.
  scene.joints[fly].guess = 0.7;
  const int fly_body = [&] {
    for (size_t b = 0; b < scene.bodies.size(); ++b)
      if (scene.bodies[b].name == "flywheel") return static_cast<int>(b);
    return -1;
  }();
  ASSERT_GE(crank, 0);
  ASSERT_GE(fly, 0);
  ASSERT_GE(fly_body, 0);
  ASSERT_EQ(scene.gears.size(), 1u);
  const double r = scene.gears[0].ratio, c = models::calc_gear_offset(scene, scene.gears[0]);
  ASSERT_EQ(r, 3.0);
  ASSERT_GT(std::abs(c), 0.1);

  const FullModel folded(scene), plain(scene, unfolded());
  ASSERT_TRUE(folded.is_folded("flywheel"));
  ASSERT_FALSE(plain.is_folded("flywheel"));
  EXPECT_EQ(plain.num_simbody_bodies(), folded.num_simbody_bodies() + 1);
  const FullModel::Impl &fi = folded.impl(), &pi = plain.impl();
  ASSERT_TRUE(fi.joint_fold[fly].has_value());
  EXPECT_EQ(fi.joint_fold[fly]->driver_joint, crank);
  EXPECT_FALSE(pi.joint_fold[fly].has_value());

  FullWorkspace fw(folded), pw(plain);
  for (double dq : {0.0, 0.4, 1.3, 2.5}) {
    const double q = scene.initial.q + dq, qdot = 6.0 - dq;
    const auto kf = calc_kinetostatic(folded, fw, q, qdot, 0.0, Loads::Off);
    const auto kp = calc_kinetostatic(plain, pw, q, qdot, 0.0, Loads::Off);
    const SimTK::State &sf = fw.impl().state, &sp = pw.impl().state;
    pi.system.realize(sp, SimTK::Stage::Velocity);
    // Same configuration of the driver in both models.
    EXPECT_NEAR(fi.joint_q(sf, crank), q, 1e-12);
    EXPECT_NEAR(pi.joint_q(sp, crank), q, 1e-12);
    // Folded (through the gear) against unfolded (Simbody's own coordinate of the flywheel).
    EXPECT_NEAR(fi.joint_q(sf, fly), r * q + c, 1e-12 * (1 + std::abs(r * q)));
    EXPECT_NEAR(fi.joint_q(sf, fly), pi.joint_q(sp, fly), 1e-9) << "crank at " << q;
    EXPECT_NEAR(fi.joint_u(sf, fly), r * qdot, 1e-12 * (1 + std::abs(r * qdot)));
    EXPECT_NEAR(fi.joint_u(sf, fly), pi.joint_u(sp, fly), 1e-9) << "crank at " << q;
    EXPECT_NEAR(fi.body_rate(sf, fly_body), pi.body_rate(sp, fly_body), 1e-9) << "crank at " << q;
    // The folded inertia r²·I on the crank carries the flywheel's kinetic energy ½ I (r q̇)².
    EXPECT_NEAR(kf.kinetic_energy, kp.kinetic_energy, 1e-9 * kp.kinetic_energy) << "crank at " << q;
    EXPECT_GT(kp.kinetic_energy, 0.5 * scene.bodies[fly_body].inertia_kgm2 * std::pow(r * qdot, 2));
  }
}

// A four-bar: three joint coordinates, one loop of two rows of full rank — one degree of freedom
// (the constraint actuator's slider for rocker_axial is not a mobility of the mechanism).
TEST(FullModelImpl, FourBarHasThreeMobilitiesLessTwoIndependentRows) {
  const models::Scene scene = models::load_scene("fourbar");
  ASSERT_FALSE(scene.outputs.constraint_forces.empty());
  const FullModel model(scene);
  FullWorkspace ws(model);
  int mobilities = 0, rows = 0, rank = 0;
  calc_mobility_count(model.impl(), ws.impl().state, mobilities, rows, rank);
  EXPECT_EQ(mobilities, 3);
  EXPECT_EQ(rows, 2);
  EXPECT_EQ(rank, 2);
  EXPECT_EQ(mobilities - rank, 1);
}

// The unfolded flywheel adds one mobility and one gear row; both counts give one degree of freedom.
TEST(FullModelImpl, UnfoldedGearAddsOneMobilityAndOneRow) {
  const models::Scene scene = models::load_scene("bicycle");
  const FullModel folded(scene), plain(scene, unfolded());
  FullWorkspace fw(folded), pw(plain);
  int fm = 0, fr = 0, fk = 0, pm = 0, pr = 0, pk = 0;
  calc_mobility_count(folded.impl(), fw.impl().state, fm, fr, fk);
  calc_mobility_count(plain.impl(), pw.impl().state, pm, pr, pk);
  // Folded: hips, knees, crank (5 joints), two pedal loops (2 rows each).
  EXPECT_EQ(fm, 5);
  EXPECT_EQ(fr, 4);
  EXPECT_EQ(pm, fm + 1);
  EXPECT_EQ(pr, fr + 1);
  EXPECT_EQ(fm - fk, 1);
  EXPECT_EQ(pm - pk, 1);
}

}  // namespace
}  // namespace rdyn::engine
