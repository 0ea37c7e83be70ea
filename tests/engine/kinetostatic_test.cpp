// Kinetostatic calls against closed forms and against a second route through Simbody.
#include "engine/kinetostatic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <tuple>

#include "models/scene_yaml.hpp"
#include "test_scenes.hpp"

namespace rdyn::engine {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Crank-rocker of models/scenes/fourbar.yaml: the rocker angle from the crank angle by
// intersecting circle(B, coupler) with circle(D, rocker), C above the line B–D.
struct FourBarPose {
  double coupler_abs, rocker;
};
FourBarPose fourbar_closed_form(double th) {
  const double a = 0.08, b = 0.28, c = 0.20, d = 0.30;
  const double Bx = a * std::cos(th), By = a * std::sin(th);
  const double dx = d - Bx, dy = -By, L = std::hypot(dx, dy);
  const double A = (b * b - c * c + L * L) / (2 * L), h = std::sqrt(b * b - A * A);
  const double ex = dx / L, ey = dy / L;
  // The left normal (−ey, ex) of B→D keeps C on the assembled side through a full turn.
  const double Cx = Bx + A * ex - h * ey, Cy = By + A * ey + h * ex;
  return {std::atan2(Cy - By, Cx - Bx), std::atan2(Cy, Cx - d)};
}

double wrap(double a) { return std::remainder(a, 2 * kPi); }

TEST(Kinetostatic, FourBarPositionsAndVelocityRatiosMatchClosedForm) {
  const auto scene = models::load_scene("fourbar");
  FullModel model(scene);
  FullWorkspace ws(model);
  const int crank = scene.joint_index("crank"), coupler = scene.joint_index("coupler"),
            rocker = scene.joint_index("rocker");
  for (int deg = 30; deg <= 390; deg += 15) {  // a full turn, continuing from point to point
    const double th = deg * kPi / 180.0;
    const auto r = calc_kinetostatic(model, ws, th, 0.0, 0.0, Loads::Off);
    const auto cf = fourbar_closed_form(th);
    EXPECT_NEAR(wrap(r.joint_q[rocker] - cf.rocker), 0.0, 1e-10) << deg;
    EXPECT_NEAR(wrap(r.joint_q[crank] + r.joint_q[coupler] - cf.coupler_abs), 0.0, 1e-10) << deg;
    const double h = 1e-6;
    const double dcf = wrap(fourbar_closed_form(th + h).rocker - fourbar_closed_form(th - h).rocker) / (2 * h);
    const auto vr = calc_velocity_ratios(model, ws, th);
    EXPECT_NEAR(vr.wrt_q[rocker], dcf, 1e-7) << deg;
    EXPECT_NEAR(vr.wrt_q[crank], 1.0, 1e-14);
  }
}

// The grid-point projection (Newton with the predicted configuration's Jacobian, from the
// second-order predictor 10°–30° away) lands on the closed-form pose to rounding: the loop
// closes to 1e-13 m, tighter than projectQ's 1e-12, so the angles agree to ~1e-12 rad.
TEST(Kinetostatic, SampleProjectionReachesTheClosedFormPose) {
  const auto scene = models::load_scene("fourbar");
  FullModel model(scene);
  const int crank = scene.joint_index("crank"), coupler = scene.joint_index("coupler"),
            rocker = scene.joint_index("rocker");
  for (int step_deg : {10, 30}) {
    FullWorkspace ws(model);
    double worst = 0.0;
    for (int deg = 0; deg <= 720; deg += step_deg) {
      const double th = deg * kPi / 180.0;
      const auto k = calc_kinetostatic_sample(model, ws, th, (step_deg + 1) * kPi / 180, SampleParts::All);
      const auto cf = fourbar_closed_form(th);
      worst = std::max({worst, std::abs(wrap(k.joint_q[rocker] - cf.rocker)),
                        std::abs(wrap(k.joint_q[crank] + k.joint_q[coupler] - cf.coupler_abs))});
      EXPECT_FALSE(k.near_singular) << deg;
    }
    EXPECT_LT(worst, 2e-12) << step_deg;
  }
}

TEST(Kinetostatic, SliderCrankPositionAndStaticTorqueMatchClosedForm) {
  const auto scene = models::load_scene("slider-crank");
  FullModel model(scene);
  FullWorkspace ws(model);
  const int slider = scene.joint_index("slider");
  const double r = 0.05, l = 0.20, F = -40.0, stall = 6.0;
  for (int deg = 30; deg <= 390; deg += 20) {
    const double th = deg * kPi / 180.0, s = std::sin(th), c = std::cos(th);
    const double root = std::sqrt(l * l - r * r * s * s);
    const double x = r * c + root;
    const double dx = -r * s - r * r * s * c / root;  // dx/dθ
    const auto st = calc_kinetostatic(model, ws, th, 0.0, 0.0, Loads::All);
    EXPECT_NEAR(st.joint_q[slider], x, 1e-11) << deg;
    // Static equilibrium by virtual work: T_act + stall + F·dx/dθ = 0 (motor at rest gives
    // its stall torque).
    EXPECT_NEAR(st.driving_force, -(stall + F * dx), 1e-9) << deg;
    const auto vr = calc_velocity_ratios(model, ws, th);
    EXPECT_NEAR(vr.wrt_q[slider], dx, 1e-11) << deg;
  }
}

TEST(Kinetostatic, ParallelogramHasConstantClosedFormInertia) {
  const auto scene = models::parse_scene(test::parallelogram_yaml(0.0, false), "parallelogram.yaml");
  FullModel model(scene);
  FullWorkspace ws(model);
  for (int deg = 40; deg <= 150; deg += 10) {
    const double q = deg * kPi / 180.0;
    const auto acc = calc_kinetostatic(model, ws, q, 0.0, 2.0, Loads::Off);   // (ii): m1 = T/α
    const auto vel = calc_kinetostatic(model, ws, q, 3.0, 0.0, Loads::Off);   // (i): m2 = T/ω²
    EXPECT_NEAR(acc.driving_force / 2.0, test::parallelogram_m1(), 1e-12) << deg;
    EXPECT_NEAR(vel.driving_force / 9.0, 0.0, 1e-12) << deg;  // m2 = ½ dm1/dq = 0
  }
}

TEST(Kinetostatic, ReducedInertiaEqualsTwiceKineticEnergyAtUnitSpeed) {
  // Two routes to m1: the actuator torque at q̇ = 0, q̈ = α, and 2·T at q̇ = 1 (T = ½ m1 q̇²).
  for (const char* name : {"bicycle", "fourbar", "slider-crank"}) {
    const auto scene = models::load_scene(name);
    FullModel model(scene);
    FullWorkspace ws(model);
    for (int deg = 0; deg < 360; deg += 45) {
      const double q = scene.initial.q + deg * kPi / 180.0;
      const double m1_acc = calc_kinetostatic(model, ws, q, 0.0, 1.5, Loads::Off).driving_force / 1.5;
      const double m1_ke = 2.0 * calc_kinetostatic(model, ws, q, 1.0, 0.0, Loads::Off).kinetic_energy;
      EXPECT_NEAR(m1_acc, m1_ke, 1e-10 * std::abs(m1_ke)) << name << " " << deg;
    }
  }
}

// calc_kinetostatic_sample makes the call (i) only and turns (ii) into virtual power
// (m1 = rᵀMr, me1 = r_xᵀMr); here every part against the separate calls it replaces, and the
// slopes dr/dq against central differences of the ratios, on both scenes with a constraint force.
TEST(Kinetostatic, OneRealizationPerGridPointAgreesWithTheSeparateCalls) {
  for (const char* name : {"fourbar", "bicycle"}) {
    const auto scene = models::load_scene(name);
    FullModel model(scene);
    FullWorkspace fast(model), ref(model);
    const int nj = static_cast<int>(scene.joints.size());
    double peak_m1 = 0, peak_me1 = 0, peak_slope = 0;
    for (int deg = 0; deg <= 360; deg += 10) {  // continuing from point to point: the predictor
      const double q = deg * kPi / 180.0;
      const auto k = calc_kinetostatic_sample(model, fast, q, 11 * kPi / 180, SampleParts::All);
      const auto i = calc_kinetostatic(model, ref, q, 1.0, 0.0, Loads::Off);
      const auto ii = calc_kinetostatic(model, ref, q, 0.0, 1.0, Loads::Off);
      const auto vr = calc_velocity_ratios(model, ref, q);
      EXPECT_NEAR(k.m1, ii.driving_force, 1e-10 * std::abs(ii.driving_force)) << name << " " << deg;
      EXPECT_NEAR(k.m2, i.driving_force, 1e-10 * std::abs(k.m1)) << name << " " << deg;
      ASSERT_EQ(k.me1.size(), 1u);
      EXPECT_NEAR(k.me1[0], ii.constraint_forces[0], 1e-10 * std::abs(k.m1)) << name << " " << deg;
      EXPECT_NEAR(k.me2[0], i.constraint_forces[0], 1e-10 * std::abs(k.m1)) << name << " " << deg;
      for (int j = 0; j < nj; ++j) {
        EXPECT_NEAR(wrap(k.joint_q[j] - i.joint_q[j]), 0.0, 1e-11) << name << " " << deg << " " << j;
        EXPECT_NEAR(k.ratio_q[j], vr.wrt_q[j], 1e-11) << name << " " << deg << " " << j;
        EXPECT_NEAR(k.ratio_x[0][j], vr.wrt_x[0][j], 1e-11) << name << " " << deg << " " << j;
        const double h = 1e-5;
        const double dr = (calc_velocity_ratios(model, ref, q + h).wrt_q[j] -
                           calc_velocity_ratios(model, ref, q - h).wrt_q[j]) / (2 * h);
        EXPECT_NEAR(k.ratio_slope[j], dr, 1e-7 * std::max(1.0, std::abs(dr))) << name << " " << deg << " " << j;
        peak_slope = std::max(peak_slope, std::abs(dr));
      }
      EXPECT_GT(k.conditioning, 1e-3);
      peak_m1 = std::max(peak_m1, std::abs(k.m1));
      peak_me1 = std::max(peak_me1, std::abs(k.me1[0]));
    }
    // Not a comparison of zeros.
    EXPECT_GT(peak_m1, 1e-3) << name;
    EXPECT_GT(peak_me1, 1e-3) << name;
    EXPECT_GT(peak_slope, 0.1) << name;
  }
}

// Without an anchor within reach the projection starts from the workspace's configuration;
// both starts reach the same configuration.
TEST(Kinetostatic, SamplePredictorReachesTheSameConfigurationAsAWalk) {
  const auto scene = models::load_scene("bicycle");
  FullModel model(scene);
  FullWorkspace a(model), b(model);
  calc_kinetostatic_sample(model, a, 0.0, 0.2, SampleParts::All);
  const auto predicted = calc_kinetostatic_sample(model, a, 0.17, 0.2, SampleParts::All);  // from the anchor
  for (double q = 0.0; q < 0.17; q += 0.01) calc_kinetostatic(model, b, q, 0, 0, Loads::Off);
  const auto walked = calc_kinetostatic_sample(model, b, 0.17, 0.0, SampleParts::All);  // no extrapolation
  for (size_t j = 0; j < scene.joints.size(); ++j)
    EXPECT_NEAR(wrap(predicted.joint_q[j] - walked.joint_q[j]), 0.0, 1e-11) << j;
  EXPECT_NEAR(predicted.m1, walked.m1, 1e-12 * walked.m1);
  const auto rates = calc_kinetostatic_sample(model, a, 0.1, 0.2, SampleParts::RatesOnly);
  EXPECT_TRUE(rates.ratio_x.empty());  // rates only
  EXPECT_EQ(rates.ratio_q.size(), scene.joints.size());
}

TEST(Kinetostatic, KneeForceFromActuatorEqualsJointReaction) {
  const auto scene = models::load_scene("bicycle");
  FullModelOptions reaction;
  reaction.route = ConstraintForceRoute::Reaction;
  FullModel act(scene), rea(scene, reaction);
  FullWorkspace wa(act), wr(rea);
  double peak = 0.0;
  for (int deg = 0; deg < 360; deg += 20) {
    const double q = deg * kPi / 180.0;
    for (const auto& [qd, qdd] : {std::pair{6.3, 0.0}, {0.0, 4.0}, {5.0, -3.0}}) {
      const double fa = calc_kinetostatic(act, wa, q, qd, qdd, Loads::All).constraint_forces.at(0);
      const double fr = calc_kinetostatic(rea, wr, q, qd, qdd, Loads::All).constraint_forces.at(0);
      EXPECT_NEAR(fa, fr, 1e-9 * std::max(1.0, std::abs(fr))) << deg << " " << qd << " " << qdd;
      peak = std::max(peak, std::abs(fr));
    }
  }
  EXPECT_GT(peak, 100.0);  // the comparison is not between zeros
}

TEST(Kinetostatic, LoopThatCannotCloseIsNamedWithItsGap) {
  std::string y = test::parallelogram_yaml(0.0, false);
  y.replace(y.find("points: {C: [0.1, 0]}"), 21, "points: {C: [0.02, 0]}");
  const auto scene = models::parse_scene(y, "short_rocker.yaml");
  FullModel model(scene);
  try {
    FullWorkspace ws(model);
    FAIL() << "assembly should fail";
  } catch (const EngineError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("short_rocker.yaml"), std::string::npos) << m;
    EXPECT_NE(m.find("loop 'C'"), std::string::npos) << m;
    EXPECT_NE(m.find("gap"), std::string::npos) << m;
  }
}

TEST(Kinetostatic, NonFinitePrescribedMotionIsANumericalError) {
  // A NaN law would project to a NaN configuration and poison the workspace's next calls.
  const auto scene = models::parse_scene(test::parallelogram_yaml(0.0, false), "p.yaml");
  FullModel model(scene);
  FullWorkspace ws(model);
  for (const auto& [q, qd, qdd] : {std::tuple{std::nan(""), 0.0, 0.0}, {0.7, INFINITY, 0.0}, {0.7, 0.0, -INFINITY}}) {
    try {
      calc_kinetostatic(model, ws, q, qd, qdd, Loads::Off);
      ADD_FAILURE() << "accepted " << q << " " << qd << " " << qdd;
    } catch (const models::NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("independent coordinate 'crank'"), std::string::npos) << e.what();
    }
  }
  // The workspace is untouched: the next finite call gives the closed-form m1 (q̈ = 1).
  EXPECT_NEAR(calc_kinetostatic(model, ws, 0.7, 0.0, 1.0, Loads::Off).driving_force, test::parallelogram_m1(), 1e-10);
}

// A point force's generalized force by two routes against the closed form T·dL/dq: inverse
// dynamics with the force applied (T_act + Q = 0 at rest: T_act = −Q = T·dL/dq) and the
// velocity ratio of its line (L̇ at q̇ = 1).
TEST(Kinetostatic, PointForceGeneralizedForceIsTensionTimesLengthRate) {
  const double T = 37.5;
  const auto scene = models::parse_scene(test::pulled_crank_yaml(T), "pulled.yaml");
  FullModel model(scene);
  FullWorkspace ws(model);
  for (double deg = -180; deg < 180; deg += 15) {
    const double q = deg * kPi / 180, dL = test::pulled_crank_dL_dq(q);
    EXPECT_NEAR(calc_kinetostatic(model, ws, q, 0, 0, Loads::All).driving_force, T * dL, 1e-10 * T) << deg;
    EXPECT_NEAR(calc_kinetostatic(model, ws, q, 0, 0, Loads::Conservative).driving_force, 0.0, 1e-12) << deg;
    const auto v = calc_velocity_ratios(model, ws, q);
    ASSERT_EQ(v.length_wrt_q.size(), 1u);
    EXPECT_NEAR(v.length_wrt_q[0], dL, 1e-12) << deg;
  }
}

// On the four-bar (a point force from ground to the coupler, a closed loop in between) the two
// Simbody routes must agree: inverse dynamics with only the force applied vs T·dL/dq from the
// line's velocity ratio; and along the constraint actuator's x the same for the force request.
TEST(Kinetostatic, PointForceOnALoopAgreesBetweenInverseDynamicsAndLengthRate) {
  const double T = 12.0;
  auto scene = models::load_scene("fourbar");
  scene.gravity.enabled = false;
  scene.resistances.clear();
  models::PointForce pf;
  pf.name = "m";
  pf.body_a = "ground";
  pf.point_a = {0.1, 0.35};
  pf.body_b = "coupler";
  pf.point_b = {0.2, 0.03};
  pf.value = T;
  scene.point_forces.push_back(pf);
  FullModel model(scene);
  FullWorkspace ws(model);
  for (double deg = 0; deg < 360; deg += 30) {
    const double q = deg * kPi / 180;
    const auto r = calc_kinetostatic(model, ws, q, 0, 0, Loads::All);
    const auto v = calc_velocity_ratios(model, ws, q);
    EXPECT_NEAR(r.driving_force, T * v.length_wrt_q.at(0), 1e-9 * T) << deg;
    ASSERT_EQ(v.length_wrt_x.size(), scene.outputs.constraint_forces.size());
    // Constraint actuator k at rest: F_E,k + Q_x,k = 0 with Q_x,k = −T·dL/dx_k.
    for (size_t k = 0; k < v.length_wrt_x.size(); ++k)
      EXPECT_NEAR(r.constraint_forces[k], T * v.length_wrt_x[k].at(0), 1e-9 * T) << deg;
    EXPECT_GT(std::abs(r.driving_force), 1e-3 * T) << deg;
  }
}

}  // namespace
}  // namespace rdyn::engine
