// The interface reduced/ extracts from (reduced/kinetostatic_source.hpp), its contract checked on
// the analytic slider-crank (analytic_source.hpp): the inertial call is Eksergian's left side
// m1 q̈ + m2 q̇² with m2 = ½ dm1/dq, the static call's driving force is dV/dq, joint rates are
// the ratios times q̇ and the ratios are the slopes of the joint coordinates, and the default
// grid sample gathers calls (i) q̇ = 1 and (ii) q̈ = 1 — each against a closed form or a second
// route.
#include "reduced/kinetostatic_source.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "analytic_source.hpp"

namespace rdyn::reduced {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Absolute-plus-relative closeness.
void expect_close(double a, double b, double abs_tol, double rel_tol, const char* what, double q) {
  EXPECT_LE(std::abs(a - b), abs_tol + rel_tol * std::max(std::abs(a), std::abs(b))) << what << " at q = " << q
                                                                                      << ": " << a << " vs " << b;
}

// m1 at the dead centre and at a quarter turn, from the mechanism (not from SliderCrank::m1):
//  θ = 0: the slider stands still, so the rod turns about it at r/l θ̇; its centre of mass,
//         l − d from the slider, moves at r (1 − d/l) θ̇.
//  θ = π/2: the rod translates with the crank pin (φ̇ = 0) and the slider follows at r θ̇.
TEST(KinetostaticSource, InertialCallGivesM1InClosedForm) {
  test::AnalyticSource src;
  const auto& c = src.sc;
  const double m1_dead = c.I_c + c.m_r * std::pow(c.r * (1 - c.d / c.l), 2) + c.I_r * std::pow(c.r / c.l, 2);
  const double m1_quarter = c.I_c + (c.m_r + c.m_s) * c.r * c.r;
  expect_close(src.inertial(0.0, 0.0, 1.0).driving_force, m1_dead, 1e-15, 1e-12, "m1", 0.0);
  expect_close(src.inertial(kPi / 2, 0.0, 1.0).driving_force, m1_quarter, 1e-15, 1e-12, "m1", kPi / 2);
  // The two differ by far more than the tolerance: the check can tell them apart.
  ASSERT_GT(std::abs(m1_quarter - m1_dead), 1e-4);
}

// m2 = ½ dm1/dq (Lagrange on T = ½ m1 q̇²): call (i) against a five-point difference of call
// (ii) with its own step (the source's m2 uses a two-point difference at 1e-5).
TEST(KinetostaticSource, VelocityCallIsHalfTheSlopeOfM1) {
  test::AnalyticSource src;
  auto m1 = [&](double q) { return src.inertial(q, 0.0, 1.0).driving_force; };
  const double h = 1e-3;
  double largest = 0;
  for (double q = -3.0; q <= 3.2; q += 0.37) {
    const double dm1 = (m1(q - 2 * h) - 8 * m1(q - h) + 8 * m1(q + h) - m1(q + 2 * h)) / (12 * h);
    const double m2 = src.inertial(q, 1.0, 0.0).driving_force;
    expect_close(m2, 0.5 * dm1, 1e-10, 1e-6, "m2", q);
    largest = std::max(largest, std::abs(m2));
  }
  EXPECT_GT(largest, 1e-4);  // not a comparison of zeros
  // m1 is even about the dead centres (the mechanism's mirror image), so m2 vanishes there.
  EXPECT_NEAR(src.inertial(0.0, 1.0, 0.0).driving_force, 0.0, 1e-12);
  EXPECT_NEAR(src.inertial(kPi, 1.0, 0.0).driving_force, 0.0, 1e-10);
}

// An inverse-dynamics call is linear in q̈ and quadratic in q̇ (Eksergian's form), for the
// driving force and every constraint force: one call at (q̇, q̈) against the two unit calls.
TEST(KinetostaticSource, InertialCallIsEksergiansLeftSide) {
  test::AnalyticSource src;
  for (double q : {-2.0, 0.3, 1.1, 2.9}) {
    const double qd = 2.5, qdd = -3.0;
    const ForcePoint both = src.inertial(q, qd, qdd);
    const ForcePoint vel = src.inertial(q, 1.0, 0.0), acc = src.inertial(q, 0.0, 1.0);
    expect_close(both.driving_force, acc.driving_force * qdd + vel.driving_force * qd * qd, 1e-14, 1e-12, "T_act", q);
    ASSERT_EQ(both.constraint_forces.size(), static_cast<size_t>(src.num_constraint_forces()));
    // The synthetic constraint line: me1 = 0.3 + 0.1 cos q, me2 = 0.2 sin 2q (analytic_source.hpp).
    expect_close(acc.constraint_forces[0], 0.3 + 0.1 * std::cos(q), 1e-15, 1e-13, "me1", q);
    expect_close(vel.constraint_forces[0], 0.2 * std::sin(2 * q), 1e-15, 1e-13, "me2", q);
    expect_close(both.constraint_forces[0], (0.3 + 0.1 * std::cos(q)) * qdd + 0.2 * std::sin(2 * q) * qd * qd,
                 1e-14, 1e-12, "F_E", q);
  }
}

// Joint rates of a call are the q-ratios times q̇, and the q-ratios are the slopes of the joint
// coordinates (central difference of joint_coordinate).
TEST(KinetostaticSource, RatiosAreRatesPerUnitQdotAndSlopesOfTheCoordinates) {
  test::AnalyticSource src;
  const double h = 1e-5;
  for (double q : {-1.3, 0.0, 0.7, 2.2}) {
    const RatioPoint r = src.ratios(q);
    ASSERT_EQ(r.wrt_q.size(), static_cast<size_t>(src.num_joints()));
    ASSERT_EQ(r.wrt_x.size(), static_cast<size_t>(src.num_constraint_forces()));
    const ForcePoint f = src.inertial(q, 1.7, 0.4);
    ASSERT_EQ(f.joint_rates.size(), r.wrt_q.size());
    for (int j = 0; j < src.num_joints(); ++j) {
      expect_close(f.joint_rates[j], 1.7 * r.wrt_q[j], 1e-15, 1e-13, "joint rate", q);
      const double slope = (*src.joint_coordinate(q + h, j) - *src.joint_coordinate(q - h, j)) / (2 * h);
      expect_close(r.wrt_q[j], slope, 1e-9, 1e-8, "ratio vs slope", q);
      EXPECT_EQ(src.ratio(q, j), r.wrt_q[j]);  // the default single-joint ratio reads the same row
    }
  }
}

// Static call with conservative loads: the driving force holds the mechanism at rest, so it is
// dV/dq (T_act = −Q); V = k (1 − cos q) in closed form.
TEST(KinetostaticSource, StaticDrivingForceIsTheSlopeOfThePotential) {
  test::AnalyticSource src;
  src.k = 3.0;
  const double h = 1e-5;
  for (double q : {-2.5, -0.4, 0.9, 1.6}) {
    const ConservativePoint c = src.conservative(q);
    expect_close(c.potential_energy, 3.0 * (1 - std::cos(q)), 1e-15, 1e-13, "V", q);
    const double dV = (src.conservative(q + h).potential_energy - src.conservative(q - h).potential_energy) / (2 * h);
    expect_close(c.forces.driving_force, dV, 1e-9, 1e-8, "T_act vs dV/dq", q);
  }
}

// The default grid sample: call (i) (q̇ = 1) in `velocity`, call (ii) (q̈ = 1) in `acceleration`,
// the static call only when asked (zeros, one per constraint force, otherwise), the ratios; the
// optional routes a source does not offer stay empty.
TEST(KinetostaticSource, DefaultSampleGathersTheUnitCalls) {
  test::AnalyticSource src;
  src.k = 2.0;
  const auto& c = src.sc;
  const GridSample g = src.sample(kPi / 2, false);
  expect_close(g.acceleration.driving_force, c.I_c + (c.m_r + c.m_s) * c.r * c.r, 1e-15, 1e-12, "m1", kPi / 2);
  expect_close(g.velocity.constraint_forces.at(0), 0.2 * std::sin(kPi), 1e-15, 0, "me2", kPi / 2);
  expect_close(g.acceleration.constraint_forces.at(0), 0.3 + 0.1 * std::cos(kPi / 2), 1e-15, 0, "me1", kPi / 2);
  EXPECT_EQ(g.conservative.forces.constraint_forces, std::vector<double>(src.num_constraint_forces(), 0.0));
  EXPECT_EQ(g.conservative.forces.driving_force, 0.0);
  EXPECT_EQ(g.conservative.potential_energy, 0.0);
  EXPECT_FALSE(g.singular);
  EXPECT_EQ(g.conditioning, 1.0);
  ASSERT_EQ(g.ratios.wrt_q.size(), 2u);
  EXPECT_NEAR(g.ratios.wrt_q[1], 0.0, 1e-15);  // the lever's ratio cos q vanishes at 90°

  const GridSample with = src.sample(kPi / 2, true);
  expect_close(with.conservative.forces.driving_force, 2.0 * std::sin(kPi / 2), 1e-15, 1e-13, "T_act", kPi / 2);
  expect_close(with.conservative.potential_energy, 2.0, 1e-15, 1e-13, "V", kPi / 2);

  const double law[5] = {0, 1, 0, 0, 0};
  EXPECT_FALSE(src.harmonic_sweep(law, 0.1).has_value());
  EXPECT_FALSE(src.direct(0.3).has_value());
  EXPECT_FALSE(src.ratio_and_slope(0.3, 0).has_value());
}

}  // namespace
}  // namespace rdyn::reduced
