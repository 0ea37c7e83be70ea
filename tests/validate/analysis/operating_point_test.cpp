// The operating point by one Newton iteration on the first integral against the nested route
// (Brent on the load, each value a fixed-point search over the speed, a secant on the
// coefficient around them): two independent solutions of the same equations must agree.
#include "validate/analysis/operating_point.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "models/scene_yaml.hpp"
#include "reduced/steady_cycle.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {
namespace {

CalibrationResult run(const models::Scene& scene, CalibrationOptions opt, bool direct) {
  opt.full_max_s = 0;
  opt.direct = direct;
  Progress quiet(false);
  return calibrate(scene, opt, quiet);
}

// Both routes on one scene: load, coefficient, cadence, dissipated power, peak force and
// speed fluctuation to 1e-8 (each route converges to ~1e-10 of its target); the Newton
// iteration in at most `max_direct` passes (every pass it made, the final cycle's included),
// the nested searches in several times as many.
void expect_routes_agree(const models::Scene& scene, const CalibrationOptions& opt, int max_direct) {
  const auto d = run(scene, opt, true), n = run(scene, opt, false);
  std::printf("%s: direct %d passes, %d load searches; nested %d passes, %d load searches\n", scene.name.c_str(),
              d.evaluations, d.load_searches, n.evaluations, n.load_searches);
  EXPECT_NEAR(d.load_value, n.load_value, 1e-8 * std::abs(n.load_value)) << scene.name;
  if (std::isfinite(n.resistance_coefficient)) {
    EXPECT_NEAR(d.resistance_coefficient, n.resistance_coefficient, 1e-8 * n.resistance_coefficient) << scene.name;
  }
  EXPECT_NEAR(d.mean_cadence_hz_reduced, opt.cadence_hz, 1e-10 * opt.cadence_hz) << scene.name;
  EXPECT_NEAR(d.mean_dissipated_power_w, n.mean_dissipated_power_w, 1e-8 * n.mean_dissipated_power_w) << scene.name;
  EXPECT_NEAR(d.peak_force_N, n.peak_force_N, 1e-8 * std::max(1.0, std::abs(n.peak_force_N))) << scene.name;
  EXPECT_NEAR(d.speed_fluctuation, n.speed_fluctuation, 1e-8) << scene.name;
  EXPECT_EQ(d.load_searches, 1) << scene.name;  // no search over loads: the Newton iteration converged
  EXPECT_LE(d.evaluations, max_direct) << scene.name;
  EXPECT_GT(n.evaluations, 3 * d.evaluations) << scene.name;
}

// The bicycle in power mode (hip torques and the brake's coefficient: 125 W at 1 Hz).
TEST(OperatingPoint, BicycleAgreesWithTheNestedSearches) {
  const auto scene = models::load_scene("bicycle");
  expect_routes_agree(scene, calibration_options_of(scene, 0.0, 0.0, ""), 12);  // measured: 8 against 96
}

// A motor-driven slider-crank whose speed varies 2.4× per turn, in power mode (the case where
// c = P/ω² was 25 % off): three unknowns with strongly coupled residuals.
TEST(OperatingPoint, FluctuatingMotorDriveAgreesWithTheNestedSearches) {
  auto scene = models::load_scene("slider-crank");
  models::Resistance drag;
  drag.name = "drag", drag.body = "crank", drag.law = models::ResistanceLaw::Viscous, drag.coefficient = 1e-3;
  scene.resistances.push_back(drag);
  // Measured: 23 passes against 283 (the constant-speed guesses stall the first pass; the
  // Jacobian is refreshed twice on the way).
  expect_routes_agree(scene, calibration_options_of(scene, 5.0, 20.0, "motor"), 30);
  // Mean-speed mode (the coefficient as given): two unknowns; measured 18 passes against 96.
  expect_routes_agree(scene, calibration_options_of(scene, 5.0, 0.0, "motor"), 24);
}

// The solver alone on its residuals: at the returned point one more pass closes the cycle,
// holds the cadence and dissipates the power, each to the solver's own tolerance.
TEST(OperatingPoint, ReturnedPointMeetsEveryResidual) {
  const auto scene = models::load_scene("bicycle");
  auto opt = calibration_options_of(scene, 0.0, 0.0, "");
  const auto e = extract_from_full(scene, opt.grid_deg, reduced::Method::Kinetostatic);
  auto m = reduced::make_reduced_model(e.samples, with_unit_load(scene, opt), reduced::Interpolation::Fourier);
  ASSERT_EQ(m.brakes.size(), 1u);
  std::vector<double> unit;  // with_unit_load: every joint torque at ±1, signs kept
  for (const auto& tq : m.torques) unit.push_back(tq.value);
  auto apply = [&](double T, double c) {
    for (size_t k = 0; k < unit.size(); ++k) m.torques[k].value = unit[k] * T;
    m.brakes[0].coefficient = c;
  };
  OperatingPointTargets t;
  t.q_section = scene.initial.q;
  t.qdot_guess = 2 * M_PI;
  t.cadence_hz = 1.0;
  t.power_w = 125.0;
  int passes = 0;
  // Guesses 30 % off: the iteration still converges, with step halving if it must.
  const auto op = solve_operating_point(m, t, 1.3 * 64.7, 0.7 * calc_resistance_coefficient(scene, opt), apply, passes);
  ASSERT_TRUE(op.has_value());
  EXPECT_LE(passes, t.max_passes);
  apply(op->load, op->coefficient);
  reduced::SteadyCycleOptions so;
  so.q_section = t.q_section;
  so.qdot_guess = op->qdot_section;
  reduced::CyclePasses cp(m, so);
  const auto p = cp.run(0.5 * op->qdot_section * op->qdot_section);
  ASSERT_TRUE(p.completed);
  const double u = 0.5 * op->qdot_section * op->qdot_section;
  EXPECT_LT(std::abs(p.u_end / u - 1), 1e-10);
  EXPECT_LT(std::abs(p.period_s - 1.0), 1e-10);
  EXPECT_LT(std::abs(-p.work_brakes_J / p.period_s / 125.0 - 1), 1e-9);
  // Steady: the drive's work per cycle equals what the resistance dissipates (V periodic), to
  // the interpolation residual of a table whose m2 is not ½ dm1/dq exactly (§5: ~1e-6).
  EXPECT_NEAR(p.work_nc_J, 0.0, 1e-5 * std::abs(p.work_brakes_J));
}

// Where the first integral does not apply the solver says so (no value), and calibrate falls
// back: a start speed that stalls before the first turn completes.
TEST(OperatingPoint, AStallingStartIsNoResult) {
  const auto scene = models::load_scene("bicycle");
  auto opt = calibration_options_of(scene, 0.0, 0.0, "");
  const auto e = extract_from_full(scene, opt.grid_deg, reduced::Method::Kinetostatic);
  auto m = reduced::make_reduced_model(e.samples, with_unit_load(scene, opt), reduced::Interpolation::Fourier);
  OperatingPointTargets t;
  t.q_section = scene.initial.q;
  t.qdot_guess = 0.01;  // 0.01 rad/s: the legs' weight stops it within the turn
  t.cadence_hz = 1.0;
  int passes = 0;
  const auto op = solve_operating_point(
      m, t, 1e-3, NAN, [&](double T, double) { for (auto& tq : m.torques) tq.value = T; }, passes);  // all +
  EXPECT_FALSE(op.has_value());
  EXPECT_GE(passes, 1);
}

}  // namespace
}  // namespace rdyn::validate
