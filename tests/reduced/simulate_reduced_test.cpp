// Bounds of the reduced integrators: options checked before work, step and wall-time budgets,
// no non-finite value in an output.
#include "reduced/simulate_reduced.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>

#include "analytic_source.hpp"
#include "reduced/extract.hpp"

namespace rdyn::reduced {
namespace {

// The analytic slider-crank (no loads): it turns freely from q̇ = 10 rad/s.
ReducedModel free_crank() {
  test::AnalyticSource src;
  ExtractOptions opt;
  opt.step_rad = 10 * M_PI / 180;
  const auto scene = test::analytic_scene();
  return make_reduced_model(extract_samples(src, scene, opt), scene, Interpolation::CubicSpline);
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(SimulateReduced, OptionsOutOfRangeAreRefusedNamingTheRange) {
  const auto m = free_crank();
  struct Case {
    const char* what;
    std::function<void(ReducedOptions&)> set;
    const char* expected;
  };
  const std::vector<Case> cases = {
      {"duration NaN", [](ReducedOptions& o) { o.duration_s = NAN; }, "duration nan s must be finite and positive"},
      {"duration inf", [](ReducedOptions& o) { o.duration_s = INFINITY; }, "must be finite and positive"},
      {"duration 0", [](ReducedOptions& o) { o.duration_s = 0; }, "must be finite and positive"},
      {"interval -1", [](ReducedOptions& o) { o.output_interval_s = -1; }, "output interval -1 s must be finite"},
      {"too many rows", [](ReducedOptions& o) { o.duration_s = 1e4, o.output_interval_s = 1e-4; },
       "gives 1e+08 output rows, more than the limit of 10000000"},
      {"tolerance too tight", [](ReducedOptions& o) { o.tolerance = 1e-15; }, "tolerance 1e-15 is out of range [1e-14, 0.1]"},
      {"tolerance too loose", [](ReducedOptions& o) { o.tolerance = 0.5; }, "out of range [1e-14, 0.1]"},
      {"tolerance NaN", [](ReducedOptions& o) { o.tolerance = NAN; }, "out of range [1e-14, 0.1]"},
      {"unknown integrator", [](ReducedOptions& o) { o.integrator = "euler"; }, "unknown reduced integrator 'euler'"},
      {"fixed step too small", [](ReducedOptions& o) { o.integrator = "rk4-fixed", o.fixed_step_s = 1e-8; },
       "fixed step 1e-08 s is out of range [1e-07, 1] s"},
      {"fixed step too large", [](ReducedOptions& o) { o.integrator = "rk4-fixed", o.fixed_step_s = 2; },
       "out of range [1e-07, 1] s"},
      {"fixed steps over budget",
       [](ReducedOptions& o) { o.integrator = "rk4-fixed", o.duration_s = 100, o.output_interval_s = 1, o.fixed_step_s = 1e-7; },
       "needs 1e+09 steps, more than the budget of 100000000"},
      {"no budget", [](ReducedOptions& o) { o.max_wall_s = 0; }, "budgets must be positive"},
  };
  for (const auto& c : cases) {
    ReducedOptions o;
    o.duration_s = 1.0;
    c.set(o);
    std::string msg;
    try {
      simulate_reduced(m, 0.0, 10.0, o);
    } catch (const TableError& e) {
      msg = e.what();
    }
    EXPECT_NE(msg.find(c.expected), std::string::npos) << c.what << ": got '" << msg << "'";
  }
  ReducedOptions o;
  EXPECT_THROW(simulate_reduced(m, NAN, 10.0, o), TableError);
  EXPECT_THROW(simulate_reduced(m, 0.0, INFINITY, o), TableError);
  EXPECT_THROW(AdaptiveIntegrator(m, 1e-16), TableError);
}

TEST(SimulateReduced, AdaptiveStepBudgetStopsTheRunNamingTheTimeReached) {
  const auto m = free_crank();
  ReducedOptions o;
  o.duration_s = 10.0;
  o.tolerance = 1e-12;
  const auto full = simulate_reduced(m, 0.0, 10.0, o);
  ASSERT_GT(full.stats.steps_attempted, 200);  // the budget below is really binding
  o.max_steps = 100;
  try {
    simulate_reduced(m, 0.0, 10.0, o);
    ADD_FAILURE() << "the step budget was not enforced";
  } catch (const models::NumericalError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("budget of 100 steps"), std::string::npos) << msg;
    // The time reached is named, and it lies inside the run.
    const auto at = msg.find("stopped at t = ");
    ASSERT_NE(at, std::string::npos) << msg;
    const double t = std::stod(msg.substr(at + 15));
    EXPECT_GT(t, 0.0);
    EXPECT_LT(t, o.duration_s);
  }
}

TEST(SimulateReduced, WallTimeBudgetStopsAdaptiveAndFixedStepRuns) {
  const auto m = free_crank();
  for (const char* integrator : {"rk8pd", "rk4-fixed"}) {
    ReducedOptions o;
    o.integrator = integrator;
    o.duration_s = 1e3;  // far more than the budget allows (~10⁶ steps at these settings)
    o.output_interval_s = 1.0;
    o.tolerance = 1e-13;
    o.fixed_step_s = 1e-5;
    o.max_wall_s = 0.05;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      simulate_reduced(m, 0.0, 10.0, o);
      ADD_FAILURE() << integrator << ": the wall-time budget was not enforced";
    } catch (const models::NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("wall-time budget of 0.05 s"), std::string::npos) << e.what();
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(wall, 5.0) << integrator;  // stopped near its budget, not at the end of the run
  }
}

TEST(SimulateReduced, NonFiniteOutputFailsTheRun) {
  // m2 = 1e300 with q̇ = 1e10: m2 q̇² overflows, so q̈ is −∞ from the first sample.
  test::AnalyticSource src;
  ExtractOptions eo;
  eo.step_rad = 10 * M_PI / 180;
  const auto scene = test::analytic_scene();
  auto s = extract_samples(src, scene, eo);
  for (auto& v : s.columns[s.require("m2")]) v = 1e300;
  const auto m = make_reduced_model(s, scene, Interpolation::Linear);
  for (const char* integrator : {"rk8pd", "rk4-fixed"}) {
    ReducedOptions o;
    o.integrator = integrator;
    const std::string msg = message_of([&] { simulate_reduced(m, 0.0, 1e10, o); });
    EXPECT_NE(msg.find("q̈ is not finite"), std::string::npos) << integrator << ": " << msg;
    EXPECT_THROW(simulate_reduced(m, 0.0, 1e10, o), models::NumericalError);
  }
}

}  // namespace
}  // namespace rdyn::reduced
