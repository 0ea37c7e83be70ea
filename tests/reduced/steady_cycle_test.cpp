// The steady cycle by the first integral against closed forms, against the time-stepping
// Poincaré map, and against the energy balance per cycle.
#include "reduced/steady_cycle.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <string>

#include "analytic_source.hpp"
#include "cli_table.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/extract.hpp"
#include "reduced/simulate_reduced.hpp"

namespace rdyn::reduced {
namespace {

// The analytic source's scene and table, with the given loads declared before extraction
// (they decide the ratio columns and switch angles the table carries).
Samples analytic_samples(const models::Scene& scene, double k, double grid_deg = 10) {
  test::AnalyticSource src;
  src.k = k;
  ExtractOptions opt;
  opt.step_rad = grid_deg * M_PI / 180;
  return extract_samples(src, scene, opt);
}

// A flywheel: constant m1 = I, m2 = 0, no potential, loads on the crank (ratio 1).
constexpr double kFlywheelInertia = 0.05;  // [kg·m²]
ReducedModel flywheel(const models::Scene& scene) {
  Samples s = analytic_samples(scene, 0.0);
  for (auto& v : s.columns[s.require("m1")]) v = kFlywheelInertia;
  for (auto& v : s.columns[s.require("m2")]) v = 0.0;
  return make_reduced_model(s, scene, Interpolation::Fourier);
}

models::Scene flywheel_scene(double torque, models::ResistanceLaw law, double coefficient) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "crank", torque, std::nullopt});
  scene.resistances.push_back({"brake", "crank", law, coefficient});
  return scene;
}

SteadyCycleOptions options(double qdot_guess, double q_section = 0.0) {
  SteadyCycleOptions o;
  o.q_section = q_section;
  o.qdot_guess = qdot_guess;
  return o;
}

double rel(double a, double b) { return std::abs(a - b) / std::max(std::abs(a), std::abs(b)); }

TEST(SteadyCycle, FlywheelWithViscousResistanceTurnsAtTorqueOverCoefficient) {
  // I q̈ = T − c q̇: steady q̇ = T/c, period 2π c/T, no fluctuation; in either direction.
  for (double T : {2.0, -2.0}) {
    const auto m = flywheel(flywheel_scene(T, models::ResistanceLaw::Viscous, 0.1));
    for (auto route : {calc_steady_cycle, calc_steady_cycle_time_stepping}) {
      const auto c = route(m, options(T > 0 ? 5.0 : -5.0, 0.7));
      EXPECT_NEAR(c.qdot_section, T / 0.1, 1e-10 * 20) << cycle_method_name(c.method);
      EXPECT_NEAR(c.period_s, 2 * M_PI * 0.1 / std::abs(T), 1e-10 * c.period_s);
      EXPECT_NEAR(c.mean_cadence_hz, std::abs(T) / 0.1 / (2 * M_PI), 1e-10);
      EXPECT_NEAR(c.speed_min, 20.0, 1e-9);
      EXPECT_NEAR(c.speed_max, 20.0, 1e-9);
      EXPECT_LT(c.speed_fluctuation, 1e-10);
      // Drive work T·2π per cycle, all dissipated.
      EXPECT_NEAR(c.drive_work_J, std::abs(T) * 2 * M_PI, 1e-9);
      EXPECT_NEAR(c.dissipated_work_J, std::abs(T) * 2 * M_PI, 1e-8);
      EXPECT_NEAR(c.drive_power_W, T * T / 0.1, 1e-8);
    }
  }
}

TEST(SteadyCycle, FlywheelWithAProfiledTorqueDoesA0TwoPiPerTurn) {
  // τ(θ) = a0 + a1 cos θ of the crank angle on a flywheel I with viscous resistance c: the
  // cos θ part does no work per turn, so on the steady cycle a0·2π = c ∫ω dθ, i.e. the mean of
  // ω over the angle is a0/c exactly, while ω itself fluctuates.
  const double a0 = 2.0, a1 = 1.5, c = 0.1;
  auto scene = test::analytic_scene();
  models::LoadProfile p;
  p.of = "crank";
  p.a0 = a0;
  p.a = {a1};
  scene.joint_torques.push_back({"drive", "crank", 1.0, std::nullopt, p});
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, c});
  const auto m = flywheel(scene);
  const auto fi = calc_steady_cycle(m, options(5.0, 0.7));
  EXPECT_EQ(fi.method, CycleMethod::FirstIntegral);
  EXPECT_NEAR(fi.drive_work_J, a0 * 2 * M_PI, 1e-8 * a0 * 2 * M_PI);
  EXPECT_NEAR(fi.dissipated_work_J, a0 * 2 * M_PI, 1e-8 * a0 * 2 * M_PI);  // c ∫ω dθ, integrated by the cycle
  EXPECT_GT(fi.speed_fluctuation, 0.01);  // a1 shapes the cycle
  // The time mean 2π/period is below the angle mean a0/c (slow stretches last longer).
  EXPECT_LT(2 * M_PI / fi.period_s, a0 / c);
  EXPECT_GT(2 * M_PI / fi.period_s, 0.95 * a0 / c);
  // ∫ω dθ by a second route: the reduced model integrated in time over one cycle from the
  // cycle's own section speed, ω dθ = ω² dt by the trapezoidal rule on a fine output.
  ReducedOptions ro;
  ro.duration_s = fi.period_s;
  ro.output_interval_s = fi.period_s / 20000;
  ro.tolerance = 1e-12;
  const auto ts = simulate_reduced(m, 0.7, fi.qdot_section, ro);
  double integral = 0.0;
  for (size_t i = 1; i < ts.t.size(); ++i)
    integral += 0.5 * (ts.qdot[i] * ts.qdot[i] + ts.qdot[i - 1] * ts.qdot[i - 1]) * (ts.t[i] - ts.t[i - 1]);
  EXPECT_NEAR(c * integral, a0 * 2 * M_PI, 1e-6 * a0 * 2 * M_PI);
  EXPECT_NEAR(ts.q.back() - ts.q.front(), 2 * M_PI, 1e-7);  // one turn in one period
  EXPECT_NEAR(ts.qdot.back(), fi.qdot_section, 1e-7 * fi.qdot_section);  // periodic
  // The time-stepping Poincaré map finds the same cycle.
  const auto tsc = calc_steady_cycle_time_stepping(m, options(5.0, 0.7));
  EXPECT_LT(rel(tsc.period_s, fi.period_s), 1e-8);
  EXPECT_LT(rel(tsc.speed_max, fi.speed_max), 1e-7);
}

TEST(SteadyCycle, GatedProfileSwitchesAtTheSameAnglesInBothRoutes) {
  // A lever torque value·τ(θ_lever), τ = 1 + 0.8 sin 2θ of the lever angle θ = sin q, on only
  // while the lever turns forward (cos q · q̇ > 0: switches at ±90°), against a crank brake; on
  // the flywheel the drive work per turn is the closed form value·∫ τ(sin q) cos q dq over
  // (−90°, 90°) = value·∫_{−1}^{1} (1 + 0.8 sin 2θ) dθ = 2·value.
  auto scene = test::analytic_scene();
  models::LoadProfile p;
  p.of = "lever";
  p.a0 = 1.0;
  p.b = {0.0, 0.8};
  scene.joint_torques.push_back({"drive", "lever", 1.5, models::RateGate{"lever", +1}, p});
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, 0.02});
  const auto m = flywheel(scene);
  const auto fi = calc_steady_cycle(m, options(20.0, 0.3));
  const auto ts = calc_steady_cycle_time_stepping(m, options(20.0, 0.3));
  EXPECT_EQ(fi.method, CycleMethod::FirstIntegral);
  EXPECT_NEAR(fi.drive_work_J, 2 * 1.5, 1e-7 * 3.0);
  EXPECT_NEAR(fi.dissipated_work_J, 2 * 1.5, 1e-7 * 3.0);
  EXPECT_LT(rel(fi.period_s, ts.period_s), 1e-8);
  EXPECT_LT(rel(fi.qdot_section, ts.qdot_section), 1e-8);
  EXPECT_LT(rel(fi.drive_work_J, ts.drive_work_J), 1e-7);
}

TEST(SteadyCycle, FlywheelWithQuadraticResistanceTurnsAtRootOfTorqueOverCoefficient) {
  // I q̈ = T − c2 q̇|q̇|: steady q̇ = √(T/c2). The equation is linear in u = q̇²/2, so the
  // map u ↦ Φ(u) is affine and the secant lands on the cycle at its third pass.
  const auto m = flywheel(flywheel_scene(2.0, models::ResistanceLaw::Quadratic, 0.01));
  const auto c = calc_steady_cycle(m, options(3.0));
  EXPECT_NEAR(c.qdot_section, std::sqrt(2.0 / 0.01), 1e-10 * std::sqrt(200.0));
  EXPECT_NEAR(c.period_s, 2 * M_PI / std::sqrt(200.0), 1e-10 * c.period_s);
  EXPECT_LE(c.passes, 4);
  EXPECT_NEAR(c.dissipated_work_J, 2.0 * 2 * M_PI, 1e-9);
}

TEST(SteadyCycle, FlywheelDrivenByAMotorLineSettlesWhereMotorAndResistanceBalance) {
  // τ = τ_s (1 − q̇/ω0) against c q̇: q̇ = τ_s / (c + τ_s/ω0).
  auto scene = test::analytic_scene();
  scene.motors.push_back({"motor", "crank", 3.0, 40.0});
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, 0.05});
  const auto m = flywheel(scene);
  const double expected = 3.0 / (0.05 + 3.0 / 40.0);
  for (auto route : {calc_steady_cycle, calc_steady_cycle_time_stepping}) {
    const auto c = route(m, options(10.0));
    EXPECT_NEAR(c.qdot_section, expected, 1e-10 * expected) << cycle_method_name(c.method);
    EXPECT_NEAR(c.drive_work_J, c.dissipated_work_J, 1e-10 * c.drive_work_J);
  }
}

// The analytic slider-crank (m1 varies with q) with a potential, a torque on the lever gated
// by the lever's rate (switch angles ±90°, where cos q = 0), and a viscous brake on the crank.
models::Scene gated_scene() {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 0.8, models::RateGate{"lever", +1}});
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, 0.01});
  return scene;
}

TEST(SteadyCycle, FirstIntegralAndTimeSteppingAgreeOnTheAnalyticMechanism) {
  const auto scene = gated_scene();
  for (double grid : {10.0, 5.0}) {
    const auto m = make_reduced_model(analytic_samples(scene, 0.02, grid), scene, Interpolation::Fourier);
    ASSERT_EQ(m.gates.size(), 1u);
    ASSERT_EQ(m.gates[0].roots.size(), 2u);
    for (double q_s : {0.0, 2.0}) {
      const auto fi = calc_steady_cycle(m, options(20.0, q_s));
      const auto ts = calc_steady_cycle_time_stepping(m, options(20.0, q_s));
      EXPECT_EQ(fi.method, CycleMethod::FirstIntegral);
      EXPECT_EQ(ts.method, CycleMethod::TimeStepping);
      EXPECT_LT(rel(fi.period_s, ts.period_s), 1e-8) << grid << " " << q_s;
      EXPECT_LT(rel(fi.qdot_section, ts.qdot_section), 1e-8) << grid << " " << q_s;
      ASSERT_EQ(fi.peak_force_N.size(), 1u);
      EXPECT_LT(rel(fi.peak_force_N[0], ts.peak_force_N[0]), 1e-8) << grid << " " << q_s;
      EXPECT_LT(rel(fi.speed_max, ts.speed_max), 1e-8);
      EXPECT_LT(rel(fi.speed_min, ts.speed_min), 1e-8);
      // Not a flat cycle: the inertia, potential and gate make the speed fluctuate.
      EXPECT_GT(fi.speed_fluctuation, 1e-3);
      EXPECT_EQ(fi.passes < ts.passes + 3, true);
      EXPECT_GT(fi.rhs_evaluations, 0);
      EXPECT_LT(rel(ts.dissipated_work_J, fi.dissipated_work_J), 1e-8);
    }
  }
}

TEST(SteadyCycle, DriveWorkPerCycleIsAllDissipated) {
  // Energy balance per cycle: ½ m1 q̇² + V returns to its value, so the drive's work is all
  // dissipated — exactly for the reduced equation when m2 = ½ dm1/dq and Q_cons = −dV/dq hold
  // for the interpolants (energy-consistent table; otherwise the balance is off by
  // ∫ (m2 − ½ m1') q̇² dq, the interpolation's own residual).
  const auto scene = gated_scene();
  const auto m = make_reduced_model(analytic_samples(scene, 0.02), scene, Interpolation::Fourier, true);
  for (double q_s : {0.0, 2.0}) {
    // At tolerance 1e-12: the balance holds to the integration error of u relative to the
    // kinetic energy, which exceeds the work per cycle (1e-10 leaves residuals of ~1e-9 of it).
    auto o = options(20.0, q_s);
    o.tolerance = 1e-12;
    const auto c = calc_steady_cycle(m, o);
    EXPECT_NEAR(c.drive_work_J, c.dissipated_work_J, 1e-10 * c.drive_work_J);
    EXPECT_NEAR(c.drive_power_W, c.dissipated_power_W, 1e-10 * c.drive_power_W);
    // The drive's work is T ∫ r_lever dq over the gate's half turn, cos q from −90° to 90°:
    // 2T (the table interpolates cos q to ~1e-11).
    EXPECT_NEAR(c.drive_work_J, 0.8 * 2.0, 1e-9);
  }
}

TEST(SteadyCycle, PeakForceIsTheMaximumOverTheCycleNotASample) {
  // A dense time-stepping trace of the cycle never exceeds the reported peak, and comes within
  // its own sampling error of it.
  const auto scene = gated_scene();
  const auto m = make_reduced_model(analytic_samples(scene, 0.02), scene, Interpolation::Fourier);
  SteadyCycleOptions coarse = options(20.0);
  coarse.samples = 16;  // few samples: the refinement has to find the peak
  const auto c = calc_steady_cycle(m, coarse);
  const auto fine = calc_steady_cycle(m, options(20.0));
  EXPECT_LT(rel(c.peak_force_N[0], fine.peak_force_N[0]), 1e-9);
  EXPECT_LT(rel(c.speed_max, fine.speed_max), 1e-9);
  EXPECT_LT(rel(c.speed_min, fine.speed_min), 1e-9);
  ReducedOptions ro;
  ro.duration_s = fine.period_s;
  ro.output_interval_s = fine.period_s / 20000;
  ro.tolerance = 1e-12;
  const auto tr = simulate_reduced(m, 0.0, fine.qdot_section, ro);
  double peak = 0;
  for (double f : tr.forces[0]) peak = std::max(peak, std::abs(f));
  EXPECT_LE(peak, fine.peak_force_N[0] * (1 + 1e-9));
  EXPECT_GT(peak, fine.peak_force_N[0] * (1 - 1e-5));
}

TEST(SteadyCycle, FirstIntegralAndTimeSteppingAgreeOnTheBicycle) {
  // The bicycle's 10° table from `rdyn extract`, with the scene's own loads (hip torques gated
  // by the thighs' rates, viscous flywheel brake): period, section speed and peak knee force.
  const std::string path = ::testing::TempDir() + "steady_cycle_bicycle_" + std::to_string(getpid()) + ".csv";
  ASSERT_EQ(test::extract_table_with_cli("bicycle", "10", path), 0);
  const auto scene = models::load_scene("bicycle");
  const auto samples = read_samples_csv(path);
  std::remove(path.c_str());
  const auto m = make_reduced_model(samples, scene, Interpolation::Fourier);
  const auto fi = calc_steady_cycle(m, options(2 * M_PI));
  const auto ts = calc_steady_cycle_time_stepping(m, options(2 * M_PI));
  EXPECT_LT(rel(fi.period_s, ts.period_s), 1e-8);
  EXPECT_LT(rel(fi.qdot_section, ts.qdot_section), 1e-8);
  ASSERT_EQ(fi.peak_force_N.size(), 1u);
  EXPECT_LT(rel(fi.peak_force_N[0], ts.peak_force_N[0]), 1e-8);
  EXPECT_LT(rel(ts.dissipated_work_J, fi.dissipated_work_J), 1e-8);
  // The scene's 69.7 N·m turns the crank near its 1 Hz.
  EXPECT_GT(fi.mean_cadence_hz, 0.9);
  EXPECT_LT(fi.mean_cadence_hz, 1.2);
  // Energy balance per cycle on the energy-consistent table, at tolerance 1e-13: the
  // flywheel's kinetic energy is ~13 times the work per cycle.
  const auto mc = make_reduced_model(samples, scene, Interpolation::Fourier, true);
  auto o = options(2 * M_PI);
  o.tolerance = 1e-13;
  const auto c = calc_steady_cycle(mc, o);
  EXPECT_NEAR(c.drive_work_J, c.dissipated_work_J, 1e-10 * c.drive_work_J);
  // find_steady_cycle takes the first integral when it applies.
  EXPECT_EQ(find_steady_cycle(m, options(2 * M_PI)).method, CycleMethod::FirstIntegral);
}

TEST(SteadyCycle, NoCycleOfOneSignIsANumericalError) {
  // A constant-magnitude brake stronger than the drive: every start slows to a stop.
  const auto stall = flywheel(flywheel_scene(1.0, models::ResistanceLaw::Constant, 1.5));
  try {
    calc_steady_cycle(stall, options(5.0));
    ADD_FAILURE() << "expected NumericalError";
  } catch (const models::NumericalError& e) {
    EXPECT_NE(std::string(e.what()).find("one sign"), std::string::npos) << e.what();
  }
  EXPECT_THROW(calc_steady_cycle_time_stepping(stall, options(5.0)), models::NumericalError);
  EXPECT_THROW(find_steady_cycle(stall, options(5.0)), models::NumericalError);
  // Drive and no resistance: the speed grows every cycle, there is no fixed point.
  auto free_scene = test::analytic_scene();
  free_scene.joint_torques.push_back({"drive", "crank", 1.0, std::nullopt});
  const auto runaway = flywheel(free_scene);
  EXPECT_THROW(calc_steady_cycle(runaway, options(5.0)), models::NumericalError);
  // A pendulum-like potential with a weak drive: the crank rocks, it never turns over.
  auto rock = gated_scene();
  rock.joint_torques[0].value = 0.01;
  const auto rocking = make_reduced_model(analytic_samples(rock, 5.0), rock, Interpolation::Fourier);
  EXPECT_THROW(calc_steady_cycle(rocking, options(1.0)), models::NumericalError);
  // A table that is not periodic has no cycle.
  auto part = analytic_samples(gated_scene(), 0.02);
  part.periodic = false;
  part.roots.clear();
  const auto open = make_reduced_model(part, gated_scene(), Interpolation::CubicSpline);
  EXPECT_THROW(calc_steady_cycle(open, options(20.0)), models::NumericalError);
}

TEST(SteadyCycle, OptionsOutOfRangeAreRefusedNamingTheRange) {
  const auto m = flywheel(flywheel_scene(2.0, models::ResistanceLaw::Viscous, 0.1));
  auto expect = [&](SteadyCycleOptions o, const std::string& text) {
    for (auto route : {calc_steady_cycle, calc_steady_cycle_time_stepping, find_steady_cycle}) {
      try {
        route(m, o);
        ADD_FAILURE() << "expected TableError: " << text;
      } catch (const TableError& e) {
        EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
      }
    }
  };
  expect(options(0.0), "must be finite and non-zero");
  expect(options(NAN), "must be finite and non-zero");
  expect(options(1.0, INFINITY), "must be finite");
  auto o = options(1.0);
  o.tolerance = 1.0;
  expect(o, "out of range [1e-14, 0.1]");
  o = options(1.0);
  o.samples = 3;
  expect(o, "3 samples per cycle is out of range [16, 1000000]");
  o = options(1.0);
  o.max_passes = 0;
  expect(o, "0 passes is out of range [1, 1000]");
}

}  // namespace
}  // namespace rdyn::reduced
