// Extraction on an analytic mechanism: every method recovers the known parameters.
#include "reduced/extract.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "analytic_source.hpp"

namespace rdyn::reduced {
namespace {

// m1 of the slider-crank by an independent route: ½ m1 θ̇² is the kinetic energy at θ̇ = 1,
// with the velocities of the crank, the rod's centre of mass and angle, and the slider taken
// by differentiating their positions (closed-form position kinematics, 4th-order central
// differences, h = 1e-4 rad: truncation ~1e-16), not from the source's velocity formulas.
double m1_from_positions(const test::SliderCrank& sc, double th) {
  struct Pose {
    double Gx, Gy, phi, xs;
  };
  auto pose = [&](double t) {
    const double phi = -std::asin(sc.r * std::sin(t) / sc.l);  // rod angle, slider on the x axis
    return Pose{sc.r * std::cos(t) + sc.d * std::cos(phi), sc.r * std::sin(t) + sc.d * std::sin(phi), phi,
                sc.r * std::cos(t) + sc.l * std::cos(phi)};
  };
  const double h = 1e-4;
  const Pose a = pose(th - 2 * h), b = pose(th - h), c = pose(th + h), e = pose(th + 2 * h);
  auto d = [&](double Pose::*f) { return (a.*f - 8 * (b.*f) + 8 * (c.*f) - e.*f) / (12 * h); };
  const double Gx = d(&Pose::Gx), Gy = d(&Pose::Gy), w = d(&Pose::phi), xs = d(&Pose::xs);
  return sc.I_c + sc.m_r * (Gx * Gx + Gy * Gy) + sc.I_r * w * w + sc.m_s * xs * xs;
}

TEST(Extract, KinetostaticRecoversClosedFormSliderCrankInertia) {
  test::AnalyticSource src;
  src.k = 2.0;
  const auto scene = test::analytic_scene();
  ExtractOptions opt;
  opt.step_rad = 10 * M_PI / 180;
  const Samples s = extract_samples(src, scene, opt);
  ASSERT_EQ(s.q.size(), 36u);
  double scale = 0;
  for (double q : s.q) scale = std::max(scale, m1_from_positions(src.sc, q));
  for (size_t i = 0; i < s.q.size(); ++i) {
    const double q = s.q[i];
    // Eksergian's coefficients: m1 from the kinetic energy, m2 = ½ dm1/dq (4th-order
    // differences of the independent m1, h = 1e-3: truncation ~1e-12 of the scale).
    EXPECT_NEAR(s.columns[s.require("m1")][i], m1_from_positions(src.sc, q), 1e-10 * scale) << q;
    const double h = 1e-3;
    const double dm1 = (m1_from_positions(src.sc, q - 2 * h) - 8 * m1_from_positions(src.sc, q - h) +
                        8 * m1_from_positions(src.sc, q + h) - m1_from_positions(src.sc, q + 2 * h)) /
                       (12 * h);
    EXPECT_NEAR(s.columns[s.require("m2")][i], 0.5 * dm1, 1e-8 * scale) << q;
    // The source's synthetic terms come back with the extraction's sign conventions: the
    // actuator holds the mechanism at rest, so Q_cons = −T_act and Qx_cons = −F_E, and the
    // potential V is stored as given.
    EXPECT_NEAR(s.columns[s.require("me1_F")][i], 0.3 + 0.1 * std::cos(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("me2_F")][i], 0.2 * std::sin(2 * q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("Q_cons")][i], -2.0 * std::sin(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("V")][i], 2.0 * (1 - std::cos(q)), 1e-14);
    EXPECT_NEAR(s.columns[s.require("Qx_cons_F")][i], 0.4 * std::cos(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("r_lever")][i], std::cos(q), 1e-14);
    EXPECT_NEAR(s.columns[s.require("rx_F_lever")][i], 0.5, 1e-14);
  }
  // Q_cons = −dV/dq: the two columns are consistent with each other (trapezoid over a
  // period of the sampled −Q_cons reproduces V's change between grid points to O(h²)).
  const auto& Q = s.columns[s.require("Q_cons")];
  const auto& V = s.columns[s.require("V")];
  for (size_t i = 0; i + 1 < s.q.size(); ++i)
    EXPECT_NEAR(V[i + 1] - V[i], -0.5 * (Q[i] + Q[i + 1]) * opt.step_rad, 2.0 * std::pow(opt.step_rad, 3));
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
      err = std::max(err, std::abs(s.columns[0][i] - m1_from_positions(src.sc, s.q[i])));
      scale = std::max(scale, m1_from_positions(src.sc, s.q[i]));
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

TEST(Extract, ProfiledTorqueIsTabulatedAtTheAngleOfItsJoint) {
  // tau_<load>(q) = τ(θ_of(q)) per unit amplitude: here θ_lever = sin q (analytic source).
  auto scene = test::analytic_scene();
  models::LoadProfile p;
  p.of = "lever";
  p.a0 = 0.5;
  p.a = {2.0};
  p.b = {0.0, -1.0};
  scene.joint_torques.push_back({"drive", "crank", 3.0, std::nullopt, p});
  test::AnalyticSource src;
  ExtractOptions opt;
  opt.step_rad = 15 * M_PI / 180;
  const Samples s = extract_samples(src, scene, opt);
  const int c = s.require("tau_drive");
  for (size_t i = 0; i < s.q.size(); ++i) {
    const double th = std::sin(s.q[i]);
    EXPECT_NEAR(s.columns[c][i], 0.5 + 2.0 * std::cos(th) - std::sin(2 * th), 1e-14) << s.q[i];
  }
  // A source without joint coordinates cannot tabulate it: refused, not guessed.
  struct NoCoordinates : test::AnalyticSource {
    std::optional<double> joint_coordinate(double, int) override { return std::nullopt; }
  } blind;
  EXPECT_THROW(extract_samples(blind, scene, opt), TableError);
}

// A point force needs its line's length rates from the source (dL/dq, dL/dx_k): a source that
// does not give them is refused, not guessed (the engine's source gives them:
// tests/engine/reduced_source_test.cpp checks them against the closed form).
TEST(Extract, PointForceNeedsLengthRatesFromTheSource) {
  auto scene = test::analytic_scene();
  models::PointForce pf;
  pf.name = "m";
  pf.body_a = models::kGround;
  pf.point_a = {1.0, 1.0};
  pf.body_b = scene.bodies[0].name;
  pf.value = 2.0;
  scene.point_forces.push_back(pf);
  test::AnalyticSource src;
  ExtractOptions opt;
  opt.step_rad = 15 * M_PI / 180;
  try {
    extract_samples(src, scene, opt);
    FAIL() << "extracted without length rates";
  } catch (const TableError& e) {
    EXPECT_NE(std::string(e.what()).find("length rates of point forces"), std::string::npos) << e.what();
  }
}

// A line whose points meet between grid points: a point at radius R on the turning body pulled
// toward a ground point at radius ρR and angle 3° (the 15° grid's points at 0° and 15°).
// L(q) = R·√(1 + ρ² − 2ρ cos(q − φ)), dL/dq = R²ρ sin(q − φ)/L: at ρ = 1 the points meet at φ
// (dL/dq jumps from −R to +R), the extraction stops naming the load (exit 1, as the full model);
// at ρ = 0.99 (closest 1 % of R apart) dL/dq is smooth and the table is made.
TEST(Extract, PointForceWhosePointsMeetBetweenGridPointsStops) {
  struct Line : test::AnalyticSource {
    double rho = 1.0, R = 0.1, phi = 3 * M_PI / 180;
    reduced::RatioPoint ratios(double q) override {
      auto r = test::AnalyticSource::ratios(q);
      const double L = R * std::sqrt(1 + rho * rho - 2 * rho * std::cos(q - phi));
      if (!(L >= models::limits::kMinPointForceLength_m))
        throw models::NumericalError("analytic: point force 'm' has its points closer than the limit");
      r.length_wrt_q = {R * R * rho * std::sin(q - phi) / L};
      r.length_wrt_x.assign(num_constraint_forces(), std::vector<double>{0.0});
      return r;
    }
  };
  auto scene = test::analytic_scene();
  models::PointForce pf;
  pf.name = "m";
  pf.body_a = models::kGround;
  pf.body_b = scene.bodies[0].name;
  pf.value = 2.0;
  scene.point_forces.push_back(pf);
  ExtractOptions opt;
  opt.step_rad = 15 * M_PI / 180;
  Line meets;
  try {
    extract_samples(meets, scene, opt);
    FAIL() << "extracted through the meeting";
  } catch (const models::NumericalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("point force 'm': its points meet near q = 0.0523"), std::string::npos) << m;
  }
  Line apart;
  apart.rho = 0.99;
  const Samples s = extract_samples(apart, scene, opt);
  const int c = s.require("Qpf_m");
  for (size_t i = 0; i < s.q.size(); ++i) EXPECT_EQ(s.columns[c][i], -apart.ratios(s.q[i]).length_wrt_q[0]);
}

TEST(Extract, GridMustDivideATurn) {
  test::AnalyticSource src;
  ExtractOptions opt;
  opt.step_rad = 7 * M_PI / 180;
  EXPECT_THROW(extract_samples(src, test::analytic_scene(), opt), TableError);
}

TEST(Extract, GridStepOutsideItsRangeIsRefusedBeforeAnyWork) {
  // --grid-deg 1e-6 once asked for 3.6e8 points and exhausted memory: refused first, with the
  // valid range in the message and not a single kinetostatic call.
  for (double deg : std::initializer_list<double>{NAN, INFINITY, -INFINITY, -10.0, 0.0, 1e-6, 0.005, 91.0, 120.0, 360.0}) {
    test::AnalyticSource src;
    ExtractOptions opt;
    opt.step_rad = deg * M_PI / 180;
    try {
      extract_samples(src, test::analytic_scene(), opt);
      ADD_FAILURE() << deg << "° was accepted";
    } catch (const TableError& e) {
      EXPECT_NE(std::string(e.what()).find("valid grid steps are 0.01° to 90°"), std::string::npos) << e.what();
    }
    EXPECT_EQ(src.calls, 0) << deg;
  }
  EXPECT_EQ(check_grid_step(0.01 * M_PI / 180), 36000);  // the finest grid
  EXPECT_EQ(check_grid_step(90 * M_PI / 180), 4);        // the coarsest
  EXPECT_EQ(check_grid_step(10 * M_PI / 180), 36);
  EXPECT_THROW(check_grid_step(7 * M_PI / 180), TableError);  // 51.43 points a turn
}

// The analytic source with one poisoned answer: its constraint-line force is NaN near 100°,
// as a redundant loop's least-squares solve can return.
class PoisonedSource : public test::AnalyticSource {
 public:
  ForcePoint inertial(double q, double qd, double qdd) override {
    auto f = AnalyticSource::inertial(q, qd, qdd);
    if (std::abs(q - 100 * M_PI / 180) < 1e-9 && qdd != 0) f.constraint_forces[0] = NAN;
    return f;
  }
};

TEST(Extract, NonFiniteSampleFailsNamingColumnAndAngle) {
  PoisonedSource src;
  ExtractOptions opt;
  opt.step_rad = 10 * M_PI / 180;
  try {
    extract_samples(src, test::analytic_scene(), opt);
    ADD_FAILURE() << "a NaN sample left extraction";
  } catch (const models::NumericalError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("column 'me1_F'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("q = 100°"), std::string::npos) << msg;
  }
}

TEST(Extract, SamplesRecordTheirScene) {
  test::AnalyticSource src;
  auto scene = test::analytic_scene();
  ExtractOptions opt;
  opt.step_rad = 30 * M_PI / 180;
  const auto a = extract_samples(src, scene, opt);
  scene.initial.q = 0.5;  // another grid anchor: another scene for a table
  const auto b = extract_samples(src, scene, opt);
  ASSERT_TRUE(a.scene_hash && b.scene_hash);
  EXPECT_NE(*a.scene_hash, *b.scene_hash);
}

TEST(Extract, TablesOverTheReaderLimitsAreRefusedBeforeAnyWork) {
  // 200 constraint forces on the analytic scene at 0.01°: 36 000 points × 1007 columns (q, then
  // 4 + 3·200 + 2 + 200·2) is over the 2·10⁷ values a table may hold, so the reader could not
  // read it back.
  struct ManyForces : test::AnalyticSource {
    int num_constraint_forces() const override { return 200; }
  } src;
  auto scene = test::analytic_scene();
  scene.outputs.constraint_forces.assign(200, scene.outputs.constraint_forces[0]);
  ExtractOptions opt;
  opt.step_rad = 0.01 * M_PI / 180;
  try {
    extract_samples(src, scene, opt);
    ADD_FAILURE() << "an oversized table was extracted";
  } catch (const TableError& e) {
    EXPECT_NE(std::string(e.what()).find("36000 points × 1007 columns"), std::string::npos) << e.what();
  }
  EXPECT_EQ(src.calls, 0);
}

}  // namespace
}  // namespace rdyn::reduced
