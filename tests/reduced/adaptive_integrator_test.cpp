// The adaptive integrator (reduced/adaptive_integrator.cpp): its steps are GSL's own step for
// step, a non-finite acceleration is said in plain words, the Hermite rows inside a step are exact
// for a quintic, and a range table's edge is the one crossed.
#include "reduced/adaptive_integrator.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <string>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "analytic_source.hpp"
#include "free_crank.hpp"
#include "reduced/extract.hpp"
#include "reduced/simulate_reduced.hpp"

namespace rdyn::reduced {
namespace {

using test::free_crank;
using test::message_of;

// AdaptiveIntegrator drives GSL's steppers itself (the start derivative and the end point come
// from the previous step instead of two more right-hand sides): on a model without gates its
// steps are gsl_odeiv2_evolve_apply's bit for bit, rejected steps included.
struct GslRhs {
  const ReducedModel* m;
  ReducedWorkspace* ws;
};
int gsl_rhs(double, const double y[], double f[], void* p) {
  auto* c = static_cast<GslRhs*>(p);
  f[0] = y[1];
  calc_acceleration(*c->m, *c->ws, y[0], y[1], f[1], f[2]);
  return std::isfinite(f[1]) ? GSL_SUCCESS : GSL_EBADFUNC;
}

TEST(AdaptiveIntegrator, AdaptiveStepsAreGslEvolveApplyStepForStep) {
  const auto m = free_crank();
  for (const char* method : {"rk8pd", "rkf45"}) {
    for (double tol : {1e-6, 1e-12}) {
      AdaptiveIntegrator integ(m, tol, method);
      integ.reset(0.0, 0.0, 10.0);
      ReducedWorkspace ws(m);
      GslRhs ctx{&m, &ws};
      gsl_odeiv2_system sys{gsl_rhs, nullptr, 3, &ctx};
      const auto* type = std::string(method) == "rk8pd" ? gsl_odeiv2_step_rk8pd : gsl_odeiv2_step_rkf45;
      gsl_odeiv2_step* st = gsl_odeiv2_step_alloc(type, 3);
      gsl_odeiv2_control* con = gsl_odeiv2_control_standard_new(tol, tol, 1.0, 1.0);
      gsl_odeiv2_evolve* ev = gsl_odeiv2_evolve_alloc(3);
      double t = 0.0, h = 1e-3, y[3] = {0.0, 10.0, 0.0};
      long n = 0;
      while (t < 1.0 && n < 100000) {
        ASSERT_EQ(gsl_odeiv2_evolve_apply(ev, con, st, &sys, &t, 1.0, &h, y), GSL_SUCCESS);
        integ.step(1.0);
        ++n;
        const auto& e = integ.step_end();
        ASSERT_EQ(e.t, t) << method << " " << tol << " step " << n;
        ASSERT_EQ(e.q, y[0]) << method << " " << tol << " step " << n;
        ASSERT_EQ(e.qdot, y[1]) << method << " " << tol << " step " << n;
        ASSERT_EQ(e.work, y[2]);
        double f[3];
        gsl_rhs(t, y, f, &ctx);
        ASSERT_EQ(e.qddot, f[1]);  // the end point's q̈ is the stepper's own end derivative
      }
      EXPECT_EQ(integ.steps(), n);
      EXPECT_EQ(integ.rejected(), static_cast<long>(ev->failed_steps));
      if (tol == 1e-12) {
        EXPECT_GT(integ.rejected(), 0) << method;  // the first 1 ms step is refused
      }
      gsl_odeiv2_evolve_free(ev);
      gsl_odeiv2_control_free(con);
      gsl_odeiv2_step_free(st);
    }
  }
}

TEST(AdaptiveIntegrator, AStepThatMeetsANonFiniteAccelerationSaysSoInPlainWords) {
  // Finite at the start, −∞ from 90° on (m2 = 1e300 at q̇ = 1e10 overflows): GSL reports
  // GSL_EBADFUNC, whose own text ("problem with user-supplied function") must not reach users.
  test::AnalyticSource src;
  ExtractOptions eo;
  eo.step_rad = 10 * M_PI / 180;
  const auto scene = test::analytic_scene();
  auto s = extract_samples(src, scene, eo);
  auto& m2 = s.columns[s.require("m2")];
  for (size_t i = 0; i < s.q.size(); ++i)
    if (s.q[i] >= M_PI / 2) m2[i] = 1e300;
  const auto m = make_reduced_model(s, scene, Interpolation::Linear);
  AdaptiveIntegrator integ(m, 1e-8);
  integ.reset(0.0, 0.0, 1e10);
  const std::string msg = message_of([&] { integ.advance(1.0); });
  EXPECT_EQ(msg.rfind("reduced integration failed at t = ", 0), 0u) << msg;
  EXPECT_NE(msg.find("): the reduced model's acceleration q̈ is not finite there"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("user-supplied"), std::string::npos) << msg;
}

TEST(AdaptiveIntegrator, HermiteRowsAreExactForAQuinticAndItsDerivative) {
  // q(t) = 1 + 2t − 3t² + 0.5t³ + 4t⁴ − 1.5t⁵ is fixed by q, q̇, q̈ at both ends of a step: the
  // quintic Hermite reproduces it (and q̇) to rounding anywhere inside; W is cubic Hermite through
  // (W, P): exact for W(t) = t³ − t (P = 3t² − 1).
  auto q = [](double t) { return 1 + t * (2 + t * (-3 + t * (0.5 + t * (4 - 1.5 * t)))); };
  auto v = [](double t) { return 2 + t * (-6 + t * (1.5 + t * (16 - 7.5 * t))); };
  auto a = [](double t) { return -6 + t * (3 + t * (48 - 30 * t)); };
  auto W = [](double t) { return t * t * t - t; };
  auto P = [](double t) { return 3 * t * t - 1; };
  const double t0 = 0.2, t1 = 0.9;
  const AdaptiveIntegrator::Point pa{t0, q(t0), v(t0), a(t0), W(t0), P(t0)}, pb{t1, q(t1), v(t1), a(t1), W(t1), P(t1)};
  for (double s : {0.0, 0.1, 0.37, 0.5, 0.93, 1.0}) {
    const double t = t0 + s * (t1 - t0);
    double qq, vv, ww;
    calc_hermite(pa, pb, s, qq, vv, ww);
    EXPECT_NEAR(qq, q(t), 1e-14) << s;
    EXPECT_NEAR(vv, v(t), 1e-13) << s;
    EXPECT_NEAR(ww, W(t), 1e-14) << s;
  }
}

TEST(AdaptiveIntegrator, OnlyTheAdaptiveMethodsAreNamedAdaptive) {
  for (const char* name : {"rk8pd", "rkf45", "rkck"}) EXPECT_TRUE(is_adaptive_method(name)) << name;
  for (const char* name : {"rk4-fixed", "RK8PD", "", "rk8"}) EXPECT_FALSE(is_adaptive_method(name)) << name;
}

// A drive stalled against a rate-gated load: +1 N·m always, −2 N·m while the crank turns
// forward. The crank stops; from then on every step of either sign flips the gate (Zeno
// chattering at rest) and steps shrink to the event location's ~1e-14 s. The run stops at the
// stall, early, naming the steps it would need (the shaper of issue #23, a motor stalled by its
// cutting force, ran for minutes where the full model stopped in seconds). A gated load that
// does not stall (−0.5 N·m) runs to the end.
TEST(AdaptiveIntegrator, AStalledDriveAtAGateStopsEarlyNamingTheStepsItWouldNeed) {
  auto run = [](double cut_Nm) {
    auto scene = test::analytic_scene();
    scene.joint_torques.push_back({"drive", "crank", 1.0, std::nullopt});
    scene.joint_torques.push_back({"cut", "crank", cut_Nm, models::RateGate{"crank", +1}});
    test::AnalyticSource src;
    ExtractOptions eo;
    eo.step_rad = 10 * M_PI / 180;
    const auto m = make_reduced_model(extract_samples(src, scene, eo), scene, Interpolation::CubicSpline);
    ReducedOptions opt;
    opt.duration_s = 10.0, opt.output_interval_s = 0.01;
    return simulate_reduced(m, 0.0, 2.0, opt);
  };
  const auto t0 = std::chrono::steady_clock::now();
  const std::string msg = message_of([&] { run(-2.0); });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_NE(msg.find("it would need ~"), std::string::npos) << msg;
  EXPECT_NE(msg.find("of 10 s"), std::string::npos) << msg;
  EXPECT_LT(wall, 10.0) << msg;  // measured well under 1 s; the wall-time budget is 600 s
  const auto ts = run(-0.5);
  EXPECT_NEAR(ts.t.back(), 10.0, 1e-12);
}

TEST(AdaptiveIntegrator, AGateWindowIsLocatedFromTheSwitchAnglesAStepPasses) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"tool", "crank", 1.0, models::RateGate{"crank", +1}});
  test::AnalyticSource src;
  ExtractOptions eo;
  eo.step_rad = 10 * M_PI / 180;
  auto m = make_reduced_model(extract_samples(src, scene, eo), scene, Interpolation::CubicSpline);
  ASSERT_EQ(m.gates.size(), 1u);
  set_gate_roots(m.gates[0], {0.1, 0.2});
  EXPECT_DOUBLE_EQ(calc_gate_window_fraction(m, 0, 0.0, 0.3), 0.5);   // the middle, 0.15
  EXPECT_DOUBLE_EQ(calc_gate_window_fraction(m, 0, 0.3, 0.0), 0.5);   // backwards: the same window
  EXPECT_DOUBLE_EQ(calc_gate_window_fraction(m, 0, 0.0, 0.15), 1.0);  // one angle: its sign changes
  EXPECT_DOUBLE_EQ(calc_gate_window_fraction(m, 0, 0.0, 0.1), 1.0);   // an end on an angle: not inside
  // Every turn's copy on a periodic table: from 2π + 0.05 to 2π + 0.45, the window at 2π + 0.15.
  EXPECT_NEAR(calc_gate_window_fraction(m, 0, 2 * M_PI + 0.05, 2 * M_PI + 0.45), 0.25, 1e-12);
  // Two turns in one step: the first window met, going down from 0.3 it is the one at 0.15.
  EXPECT_NEAR(calc_gate_window_fraction(m, 0, 0.3, 0.3 - 4 * M_PI), (0.15 - 0.3) / (-4 * M_PI), 1e-12);
}

// A torque on the crank gated on over 0.03 rad a turn (switch angles 0.1 and 0.13 set on the
// model: the switching function −sin((q − 0.1)/2)·sin((q − 0.13)/2)·q̇ is positive only between
// them) does T·0.03 of work at every pass, whatever its timing. The free crank at ~30 rad/s passes
// the window in ~1 ms, inside one rk8pd step at 1e-8: 2 switches of 36 were seen and the work was
// 0.03 J of 0.27 J (a five-bar's forces came out 60 % off, exit 0). Located, every pass's to 1e-7.
TEST(AdaptiveIntegrator, AGateWindowInsideOneStepIsNotSteppedOver) {
  auto scene = test::analytic_scene();
  constexpr double kT = 0.5, kA = 0.1, kB = 0.13;
  scene.joint_torques.push_back({"tool", "crank", kT, models::RateGate{"crank", +1}});
  test::AnalyticSource src;
  ExtractOptions eo;
  eo.step_rad = 10 * M_PI / 180;
  auto m = make_reduced_model(extract_samples(src, scene, eo), scene, Interpolation::CubicSpline);
  ASSERT_EQ(m.gates.size(), 1u);
  set_gate_roots(m.gates[0], {kA, kB});
  m.gates[0].root_sign = -1.0;
  ReducedOptions opt;
  opt.duration_s = 3.0, opt.output_interval_s = 0.01;
  const auto ts = simulate_reduced(m, 1.0, 30.0, opt);
  const double q_end = ts.q.back();
  int passes = 0;
  for (int k = 0; kB + 2 * M_PI * k < q_end; ++k)
    if (kA + 2 * M_PI * k > 1.0) ++passes;
  ASSERT_GE(passes, 3);
  EXPECT_EQ(ts.stats.events, 2 * passes);  // on and off at every pass
  EXPECT_NEAR(ts.work.back(), passes * kT * (kB - kA), 1e-7 * passes * kT * (kB - kA));
}

}  // namespace
}  // namespace rdyn::reduced
