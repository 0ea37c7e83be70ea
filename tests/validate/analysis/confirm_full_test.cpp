// The full-model confirmation: the window's measures against closed forms of a uniformly
// accelerated rotation, a crank turning at constant speed on the full model (cadence ω/2π,
// centripetal pin force m·r·ω²), and the calibrated bicycle, whose full-model cadence must hold
// the target within 1 % and whose measures must agree with a direct engine run.
#include "validate/analysis/confirm_full.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {
namespace {

constexpr double kTwoPi = 2 * M_PI;

// q(t) = q0 + ω0 t + ½ α t² sampled every dt, with a force F = 3 + cos q (a function of the angle
// alone, so its by-angle curve is known).
models::TimeSeries accelerated(double q0, double w0, double alpha, double duration, double dt) {
  models::TimeSeries ts;
  ts.forces.resize(1);
  for (long i = 0; i * dt <= duration + 1e-12; ++i) {
    const double t = i * dt, q = q0 + w0 * t + 0.5 * alpha * t * t;
    ts.t.push_back(t);
    ts.q.push_back(q);
    ts.qdot.push_back(w0 + alpha * t);
    ts.forces[0].push_back(3 + std::cos(q));
  }
  return ts;
}

TEST(ConfirmFull, WindowMeasuresMatchClosedFormsOfUniformAcceleration) {
  const double q0 = 0.3, w0 = 6.0, alpha = 0.8, T = 6.0, dt = 0.002, skip = 1.0;
  const auto ts = accelerated(q0, w0, alpha, T, dt);
  const auto c = calc_steady_window(ts, skip, 0);
  // The window's rows run from t = skip to T: mean rate = mean of ω = ω(mid-window) / 2π.
  EXPECT_NEAR(c.mean_rate_hz, (w0 + alpha * (skip + T) / 2) / kTwoPi, 1e-12);
  // Rows are uniform in t and ω linear: the mean of q̇ over the rows is ω at mid-window.
  EXPECT_NEAR(c.speed_fluctuation, alpha * (T - skip) / (w0 + alpha * (skip + T) / 2), 1e-12);
  // Whole revolutions n from q_s: ½ α τ² + ω_s τ = 2πn, cadence n/τ (linear interpolation
  // between rows 2 ms apart errs by ~α dt²/8 in q, 1e-7 of the span here).
  const double ws = w0 + alpha * skip, qs = q0 + w0 * skip + 0.5 * alpha * skip * skip;
  const double qe = q0 + w0 * T + 0.5 * alpha * T * T;
  const double n = std::floor((qe - qs) / kTwoPi);
  const double tau = (-ws + std::sqrt(ws * ws + 2 * alpha * kTwoPi * n)) / alpha;
  ASSERT_GE(n, 5);
  EXPECT_NEAR(c.cadence_hz, n / tau, 1e-7 * n / tau);
  // Whole revolutions differ from the mean over the rows (the last partial revolution is faster).
  EXPECT_GT(std::abs(c.cadence_hz - c.mean_rate_hz), 1e-4);
  EXPECT_NEAR(c.peak_force_N, 4.0, 1e-5);  // max of 3 + cos q, reached in every revolution
  ASSERT_EQ(c.force_1deg.size(), 360u);
  for (int a = 0; a < 360; ++a) EXPECT_NEAR(c.force_1deg[a], 3 + std::cos(a * M_PI / 180), 1e-4) << a;
}

TEST(ConfirmFull, WindowStartsAtSkipAndShortWindowsGiveNaN) {
  // ω jumps from 1 to 10 rad/s at t = 2 s: a window from 2 s sees only the fast part.
  models::TimeSeries ts;
  double q = 0;
  for (int i = 0; i <= 400; ++i) {
    const double t = 0.01 * i, w = t < 2.0 ? 1.0 : 10.0;
    if (i > 0) q += w * 0.01;
    ts.t.push_back(t), ts.q.push_back(q), ts.qdot.push_back(w);
  }
  const auto c = calc_steady_window(ts, 2.0, 0);
  EXPECT_NEAR(c.mean_rate_hz, 10 / kTwoPi, 1e-9);
  EXPECT_NEAR(c.cadence_hz, 10 / kTwoPi, 1e-9);
  EXPECT_EQ(c.speed_fluctuation, 0.0);
  EXPECT_TRUE(std::isnan(c.peak_force_N));  // no constraint force requested
  EXPECT_TRUE(c.force_1deg.empty());
  const auto late = calc_steady_window(ts, 3.985, 0);  // two rows left
  EXPECT_TRUE(std::isnan(late.mean_rate_hz) && std::isnan(late.cadence_hz) && std::isnan(late.speed_fluctuation));
}

// q(t) = ω t + a sin(ω t) (a < 1: q̇ = ω (1 + a cos ω t) > 0): every revolution takes exactly
// 2π/ω, however much the speed fluctuates within it.
models::TimeSeries fluctuating(double w, double a, double duration, double dt, double sign = 1.0) {
  models::TimeSeries ts;
  ts.forces.resize(1);
  for (long i = 0; i * dt <= duration + 1e-12; ++i) {
    const double t = i * dt;
    ts.t.push_back(t);
    ts.q.push_back(sign * (w * t + a * std::sin(w * t)));
    ts.qdot.push_back(sign * w * (1 + a * std::cos(w * t)));
    ts.forces[0].push_back(2 + std::sin(w * t));
  }
  return ts;
}

TEST(ConfirmFull, WholeRevolutionsHoldAFluctuatingCadenceAFixedWindowMisses) {
  // 0.45 Hz, speed swinging ±50 %: the old measure (rows from 1 s to 6 s) ends mid-revolution
  // and is off by ~4 %; whole revolutions give the cadence to the interpolation error.
  const double f = 0.45, w = kTwoPi * f, a = 0.5, dt = 0.002;
  const auto ts = fluctuating(w, a, 6.0, dt);
  const auto window = calc_steady_window(ts, 1.0, 0);
  EXPECT_GT(std::abs(window.mean_rate_hz - f) / f, 0.02);
  const auto times = calc_revolution_times(ts, 1.0);
  ASSERT_EQ(times.size(), 2u);  // 2.7 revolutions in 6 s
  for (size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], (k + 1) / f, 1e-9) << k;
  const auto m = calc_revolution_measures(ts, 1.0, 1, 0);
  EXPECT_EQ(m.revolutions, 2);
  EXPECT_NEAR(m.cadence_hz, f, 1e-9 * f);
  EXPECT_NEAR(m.previous_cadence_hz, f, 1e-9 * f);
  // Over the rows of the last revolution: q̇ from ω(1 − a) to ω(1 + a), mean ω (to one row's
  // weight, ~1e-3); F from 1 to 3 (its peak to (ω dt)²/2 between rows).
  EXPECT_NEAR(m.speed_fluctuation, 2 * a, 2e-3);
  EXPECT_NEAR(m.peak_force_N, 3.0, 1e-4);
  // Turning backwards: the same measures.
  const auto back = calc_revolution_measures(fluctuating(w, a, 6.0, dt, -1.0), -1.0, 1, 0);
  EXPECT_EQ(back.revolutions, 2);
  EXPECT_NEAR(back.cadence_hz, f, 1e-9 * f);
  EXPECT_NEAR(back.speed_fluctuation, 2 * a, 2e-3);
}

TEST(ConfirmFull, CrossingsAreInterpolatedBetweenCoarseRowsAndShortSeriesGiveNaN) {
  // Rows 50 ms apart on the fluctuating motion: the Hermite crossings still land within ~1e-6 s
  // (h⁴ q⁗/384 ≈ 3e-6 rad).
  const double f = 0.8, w = kTwoPi * f;
  const auto ts = fluctuating(w, 0.3, 10.0, 0.05);
  const auto times = calc_revolution_times(ts, 1.0);
  ASSERT_EQ(times.size(), 8u);
  for (size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], (k + 1) / f, 1e-5) << k;
  const auto m = calc_revolution_measures(ts, 1.0, 3, 0);
  EXPECT_NEAR(m.cadence_hz, f, 1e-5 * f);
  EXPECT_NEAR(m.previous_cadence_hz, f, 1e-5 * f);
  const auto few = calc_revolution_measures(fluctuating(w, 0.3, 3.0, 0.01), 1.0, 2, 0);  // 2 revolutions
  EXPECT_EQ(few.revolutions, 2);
  EXPECT_NEAR(few.cadence_hz, f, 1e-6 * f);
  EXPECT_TRUE(std::isnan(few.previous_cadence_hz));
  const auto none = calc_revolution_measures(fluctuating(w, 0.3, 1.0, 0.01), 1.0, 1, 0);
  EXPECT_EQ(none.revolutions, 0);
  EXPECT_TRUE(std::isnan(none.cadence_hz) && std::isnan(none.speed_fluctuation));
}

// One crank about O, no gravity, no loads: it turns at its initial speed, and the pin holds its
// centre of mass on a circle with the centripetal force m·r_c·ω² along the crank.
std::string free_crank_yaml(double qdot) {
  return R"(
name: free_crank
ground_points: {O: [0, 0]}
bodies:
  - {name: crank, mass_kg: 1.5, com_m: [0.05, 0], inertia_kgm2: 2.0e-3, points: {B: [0.1, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank}
independent: crank
gravity: {enabled: false}
outputs:
  constraint_forces:
    - {name: pin, joint: crank, direction: B}
initial: {q_deg: 20, qdot: )" + std::to_string(qdot) + "}\n";
}

TEST(ConfirmFull, FreeCrankKeepsItsCadenceAndCentripetalPinForce) {
  const double w = 1.3 * kTwoPi;
  const auto scene = models::parse_scene(free_crank_yaml(w), "free_crank.yaml");
  FullConfirmOptions o;
  o.duration_s = 4.0;
  o.skip_s = 1.0;
  const auto c = confirm_full(scene, o);
  const double f = std::stod(std::to_string(w)) / kTwoPi;  // the speed as written in the YAML
  EXPECT_NEAR(c.cadence_hz, f, 1e-8 * f);
  EXPECT_NEAR(c.mean_rate_hz, f, 1e-8 * f);
  EXPECT_LT(c.speed_fluctuation, 1e-8);
  const double centripetal = 1.5 * 0.05 * (kTwoPi * f) * (kTwoPi * f);
  EXPECT_NEAR(c.peak_force_N, centripetal, 1e-6 * centripetal);
  ASSERT_EQ(c.force_1deg.size(), 360u);
  for (int a = 0; a < 360; a += 15) EXPECT_NEAR(std::abs(c.force_1deg[a]), centripetal, 1e-6 * centripetal) << a;
}

TEST(ConfirmFull, SteadyRunOfAFreeCrankStopsAfterItsFirstRun) {
  const double w = 1.3 * kTwoPi;
  const auto scene = models::parse_scene(free_crank_yaml(w), "free_crank.yaml");
  SteadyConfirmOptions o;
  o.cadence_hz = 1.3;
  const auto c = confirm_full_steady(scene, o);
  const double f = std::stod(std::to_string(w)) / kTwoPi;
  EXPECT_TRUE(c.steady);
  EXPECT_EQ(c.runs, 1);
  EXPECT_NEAR(c.duration_s, 1.02 * 7 / 1.3, 1e-12);  // 2m + 1 periods, 2 % more
  EXPECT_EQ(c.measures.revolutions, 7);
  EXPECT_NEAR(c.measures.cadence_hz, f, 1e-8 * f);
  const double centripetal = 1.5 * 0.05 * (kTwoPi * f) * (kTwoPi * f);
  EXPECT_NEAR(c.measures.peak_force_N, centripetal, 1e-6 * centripetal);
}

// A wheel (J = 0.05 kg·m²) against viscous drag c = 0.02 N·m·s driven by T = 0.2 N·m: it tends
// to ω = T/c = 10 rad/s with time constant J/c = 2.5 s. Started at 20 rad/s it is not steady for
// a while: the run is repeated longer until it is, and a short cap is reported as not steady.
TEST(ConfirmFull, ATransientRunsLongerUntilSteadyOrFailsAtTheCap) {
  const auto scene = models::parse_scene(R"(
name: spin_down
bodies: [{name: wheel, mass_kg: 2.0, inertia_kgm2: 0.05}]
joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]
independent: wheel
loads:
  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}
  - {type: joint_torque, name: drive, joint: wheel, torque_Nm: 0.2}
initial: {q_deg: 0, qdot: 20.0}
)",
                                         "spin_down.yaml");
  SteadyConfirmOptions o;
  o.cadence_hz = 10 / kTwoPi;
  // 8 s, about 3 time constants: successive 3-revolution means still differ by ~2 %; steady (1e-4)
  // from about 21 s.
  o.max_duration_s = 8.0;
  const auto short_run = confirm_full_steady(scene, o);
  EXPECT_FALSE(short_run.steady);
  EXPECT_EQ(short_run.duration_s, 8.0);
  EXPECT_GT(short_run.runs, 1);
  o.max_duration_s = 120.0;
  const auto c = confirm_full_steady(scene, o);
  EXPECT_TRUE(c.steady);
  EXPECT_GT(c.runs, 1);
  // Within the steady test's 1e-4 of the final speed (the mean over 3 revolutions of an
  // exponential approach lags, so compare with the measure's own consistency).
  EXPECT_NEAR(c.measures.cadence_hz, 10 / kTwoPi, 2e-4 * 10 / kTwoPi);
}

TEST(ConfirmFull, CalibratedBicycleHoldsItsCadenceAndAgreesWithADirectRun) {
  // The reduced calibration at 1 Hz / 125 W (no full check), then the loads set as calibrate sets
  // them: every joint torque at ±T, the resistance at its coefficient, the steady start.
  const auto base = models::load_scene("bicycle");
  CalibrationOptions opt = calibration_options_of(base, 1.0, 125.0, "");
  opt.full_max_s = 0;
  Progress quiet(false);
  const auto r = calibrate(base, opt, quiet);
  auto scene = base;
  for (auto& t : scene.joint_torques) t.value = (t.value < 0 ? -1 : 1) * std::abs(r.load_value);
  scene.resistances[0].coefficient = r.resistance_coefficient;
  scene.initial.q = r.steady_q;
  scene.initial.qdot = r.steady_qdot;
  FullConfirmOptions o;
  o.duration_s = 4.0;
  o.skip_s = 1.0;
  const auto c = confirm_full(scene, o);
  EXPECT_LE(std::abs(c.mean_rate_hz - 1.0), kFullCadenceTolerance);
  EXPECT_LE(std::abs(c.cadence_hz - 1.0), kFullCadenceTolerance);
  EXPECT_NEAR(c.cadence_hz, 1.0, 1e-3);  // a genuine operating point: far inside the 1 %
  // The knee force's peak on the full model against the reduced steady cycle's (validated to 0.5 %).
  EXPECT_NEAR(c.peak_force_N, r.peak_force_N, 5e-3 * r.peak_force_N);
  EXPECT_NEAR(c.speed_fluctuation, r.speed_fluctuation, 0.05 * r.speed_fluctuation);

  // A direct engine run with the same settings, measured here from its rows.
  const engine::FullModel full(scene);
  engine::ForwardOptions fo;
  fo.duration_s = 4.0;
  fo.output_interval_s = 0.002;
  fo.tolerance = 1e-9;
  const auto ts = engine::simulate_full(full, fo);
  size_t i1 = 0;
  while (ts.t[i1] < 1.0) ++i1;
  double peak = 0;
  for (size_t i = i1; i < ts.t.size(); ++i) peak = std::max(peak, std::abs(ts.forces[0][i]));
  EXPECT_NEAR(c.mean_rate_hz, (ts.q.back() - ts.q[i1]) / (kTwoPi * (ts.t.back() - ts.t[i1])), 1e-12);
  EXPECT_NEAR(c.peak_force_N, peak, 1e-9 * peak);
}

}  // namespace
}  // namespace rdyn::validate
