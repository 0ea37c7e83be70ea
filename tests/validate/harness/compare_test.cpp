// Steady-window detection and run comparison on synthetic series with known answers.
#include "validate/harness/compare.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rdyn::validate {
namespace {

// Speed relaxing from 5 to 2π rad/s with time constant tau, q its integral.
models::TimeSeries relaxing(double tau, double T = 10, double dt = 1e-3) {
  models::TimeSeries ts;
  const double w = 2 * M_PI, w0 = 5.0;
  for (int i = 0; i * dt <= T + 1e-12; ++i) {
    const double t = i * dt;
    ts.t.push_back(t);
    ts.qdot.push_back(w + (w0 - w) * std::exp(-t / tau));
    ts.q.push_back(w * t + (w0 - w) * tau * (1 - std::exp(-t / tau)));
    ts.forces.resize(1);
    ts.forces[0].push_back(100 * std::sin(ts.q.back()));
    ts.gates.push_back(std::sin(ts.q.back()) > 0 ? 1u : 0u);
  }
  ts.force_names = {"F"};
  return ts;
}

TEST(Compare, SteadyWindowSkipsTheTransient) {
  const auto ts = relaxing(0.5);
  const auto w = detect_steady_window(ts, true, 1e-3);
  // Consecutive revolution means (≈ 1 s apart) differ by (5 − 2π)/2π · e^{−t/τ}(e^{1/τ·…} − 1)
  // ≈ 0.2·e^{−t/0.5}·… : below 1e-3 from about t ≈ 2.5 s on.
  EXPECT_GT(w.t_start, 1.5);
  EXPECT_LT(w.t_start, 4.0);
  EXPECT_GE(w.revolutions, 5);
  EXPECT_FALSE(w.whole_run);
  // Without revolutions (a rocking mechanism, a transient) the whole run is compared.
  const auto rocking = detect_steady_window(ts, false);
  EXPECT_EQ(rocking.t_start, 0.0);
  EXPECT_TRUE(rocking.whole_run);
  EXPECT_NE(rocking.how.find("whole run"), std::string::npos);
  // Two revolutions only (the first 2.1 s): still no steady cycles.
  auto short_run = ts;
  const size_t n = 2100;
  for (auto* v : {&short_run.t, &short_run.q, &short_run.qdot, &short_run.forces[0]}) v->resize(n);
  short_run.gates.resize(n);
  EXPECT_TRUE(detect_steady_window(short_run, true).whole_run);
}

// A NaN in a run is no error of 0: it stays NaN, which no threshold passes (t.error <= max).
TEST(Compare, ANanInARunIsNeverWithinAnyError) {
  auto ref = relaxing(0.5), run = ref;
  run.forces[0][4000] = NAN;
  run.forces[0][4001] += 1.0;  // a later, finite difference does not hide it
  const auto c = compare_series(ref, run, 3.0);
  EXPECT_TRUE(std::isnan(c.find("F")->max_rel));
  EXPECT_EQ(c.find("qdot")->max_rel, 0.0);
}

TEST(Compare, RelativeErrorsAndGateExclusion) {
  auto ref = relaxing(0.5), run = ref;
  for (auto& v : run.qdot) v += 0.01;
  for (auto& v : run.forces[0]) v *= 1.02;
  // One sample where the run has switched and the reference not yet: excluded.
  run.gates[5000] ^= 1u;
  run.forces[0][5000] += 1e6;
  const auto c = compare_series(ref, run, 3.0);
  EXPECT_EQ(c.excluded, 1);
  EXPECT_NEAR(c.find("qdot")->max_rel, 0.01 / c.find("qdot")->peak, 1e-12);
  EXPECT_NEAR(c.find("F")->max_rel, 0.02, 1e-9);
  EXPECT_NEAR(c.find("F")->rms_rel, 0.02 / std::sqrt(2.0), 1e-3);
  run.t.pop_back();
  EXPECT_THROW(compare_series(ref, run, 0), std::runtime_error);
}


// A rocking mechanism: q = A sin ωt, mean speed over the window near zero. Its mean-speed error
// is measured against 1 % of the peak speed, not against the near-zero mean.
TEST(Compare, MeanSpeedOfAnOscillationIsScaledByThePeakSpeed) {
  models::TimeSeries ref;
  const double A = 0.3, w = 2 * M_PI;
  for (int i = 0; i <= 1000; ++i) {
    const double t = i * 1e-3 * 1.01;  // 1.01 periods: mean speed ≈ A·sin(2π·1.01)/1.01 ≈ 0.019 rad/s
    ref.t.push_back(t);
    ref.q.push_back(A * std::sin(w * t));
    ref.qdot.push_back(A * w * std::cos(w * t));
  }
  auto run = ref;
  run.q.back() += 1e-4;  // displacement error 1e-4 rad over 1.01 s
  const auto c = compare_series(ref, run, 0.0);
  const double peak = A * w, mean_ref = (ref.q.back() - ref.q.front()) / ref.t.back();
  ASSERT_LT(std::abs(mean_ref), 0.01 * peak);  // the case this guards
  EXPECT_NEAR(c.find("mean_qdot")->max_rel, 1e-4 / ref.t.back() / (0.01 * peak), 1e-9);
  // A turning run keeps the relative error of its mean speed.
  auto turning = ref;
  for (size_t i = 0; i < turning.t.size(); ++i) turning.q[i] += 2 * M_PI * turning.t[i];
  auto turning_run = turning;
  turning_run.q.back() += 1e-4;
  const auto ct = compare_series(turning, turning_run, 0.0);
  const double mean_turning = (turning.q.back() - turning.q.front()) / turning.t.back();
  EXPECT_NEAR(ct.find("mean_qdot")->max_rel, 1e-4 / turning.t.back() / mean_turning, 1e-9);
}

}  // namespace
}  // namespace rdyn::validate

namespace rdyn::validate {
namespace {

// Joint outputs are compared by name where both runs carry them (a reaction only the full model
// gives is skipped), after the constraint forces; one that is zero but for rounding is measured
// against 1e-9 of the largest joint output, not against its own noise.
TEST(Compare, JointOutputsAreMatchedByNameAndNoiseHasAFloor) {
  auto ref = relaxing(0.5), run = ref;
  const size_t n = ref.t.size();
  ref.column_names = {"R_a_x", "R_only_full_x", "R_noise_x"};
  run.column_names = {"R_noise_x", "R_a_x"};  // another order, one missing
  ref.columns.assign(3, std::vector<double>(n));
  run.columns.assign(2, std::vector<double>(n));
  for (size_t i = 0; i < n; ++i) {
    ref.columns[0][i] = 200 * std::cos(ref.q[i]);
    run.columns[1][i] = 1.001 * ref.columns[0][i];  // 0.1 % off
    ref.columns[1][i] = 50;
    ref.columns[2][i] = 1e-11 * std::sin(1e3 * ref.t[i]);  // rounding noise
    run.columns[0][i] = -ref.columns[2][i];                 // other noise: 100 % of its own peak
  }
  const auto c = compare_series(ref, run, 3.0);
  ASSERT_NE(c.find("R_a_x"), nullptr);
  EXPECT_NEAR(c.find("R_a_x")->max_rel, 1e-3, 1e-9);
  EXPECT_EQ(c.find("R_only_full_x"), nullptr);
  ASSERT_NE(c.find("R_noise_x"), nullptr);
  EXPECT_NEAR(c.find("R_noise_x")->max_rel, 2e-11 / (1e-9 * 200), 1e-3);  // 1e-4, not 2
  EXPECT_EQ(c.signals[1].name, "F");  // forces first, then joint outputs, then the mean speed
  EXPECT_EQ(c.signals.back().name, "mean_qdot");
}

}  // namespace
}  // namespace rdyn::validate
