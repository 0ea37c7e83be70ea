// The reduced ODE on mechanisms with known answers.
#include "reduced/reduced_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <new>

#include "analytic_source.hpp"
#include "count_allocations.hpp"
#include "models/scene_hash.hpp"
#include "reduced/extract.hpp"
#include "reduced/simulate_reduced.hpp"

// Counts heap allocations in this test binary (for the allocation-free step). The
// replacements pair operator new with malloc and operator delete with free, which GCC's
// -Wmismatched-new-delete cannot see through.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
long g_allocations = 0;
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace rdyn::reduced {
namespace {

Samples analytic_samples(double k, const models::Scene& scene, double grid_deg = 10) {
  test::AnalyticSource src;
  src.k = k;
  ExtractOptions opt;
  opt.step_rad = grid_deg * M_PI / 180;
  return extract_samples(src, scene, opt);
}

TEST(ReducedModel, ConservesEnergyWithoutNonConservativeLoads) {
  // Slider-crank with a potential V = k(1 − cos q): ½ m1 q̇² + V stays constant. With m2 =
  // ½ dm1/dq of the interpolant the reduced equation is exactly conservative.
  const auto scene = test::analytic_scene();
  const auto s = analytic_samples(0.01, scene);  // V max 0.02 J below the kinetic energy: it turns
  for (bool consistent : {true, false}) {
    const auto m = make_reduced_model(s, scene, Interpolation::CubicSpline, consistent);
    ReducedOptions opt;
    opt.duration_s = 5.0;
    opt.output_interval_s = 0.01;
    opt.tolerance = 1e-12;
    opt.step_outputs = true;  // rows as accurate as the steps (Hermite rows alone are off ~1e-7)
    const auto ts = simulate_reduced(m, 0.3, 12.0, opt);
    double drift = 0;
    for (double e : ts.energy) drift = std::max(drift, std::abs(e - ts.energy[0]));
    std::printf("energy drift %s: %.3g of E0\n", consistent ? "consistent" : "inconsistent", drift / ts.energy[0]);
    // The consistent variant conserves to the integrator's tolerance; the inconsistent one
    // drifts by the interpolation error of m2 against ½ dm1/dq.
    if (consistent) {
      EXPECT_LT(drift, 3e-10 * ts.energy[0]);  // 8.4e-11 measured over 5 s at 1e-12
    } else {
      EXPECT_LT(drift, 1e-3 * ts.energy[0]);  // m1, m2 interpolated apart: small drift
      EXPECT_GT(drift, 1e-6 * ts.energy[0]);  // ... which the consistent variant removes
    }
    EXPECT_GT(ts.q.back(), 10.0);                // it really turned
  }
}

// The analytic slider-crank with V shifted by a constant: the same mechanism, another zero
// of the potential energy.
class ShiftedPotentialSource : public test::AnalyticSource {
 public:
  double offset_J = 0.0;
  ConservativePoint conservative(double q) override {
    auto c = AnalyticSource::conservative(q);
    c.potential_energy += offset_J;
    return c;
  }
};

// Time at which a fixed-step RK4 run (steps of h at 12 rad/s: too coarse for a mechanism whose
// inertia varies three-fold within a turn) is stopped by the divergence guard, or NaN.
double divergence_time(double offset_J, double h) {
  const auto scene = test::analytic_scene();
  ShiftedPotentialSource src;
  src.k = 0.01;
  src.offset_J = offset_J;
  ExtractOptions eo;
  eo.step_rad = 10 * M_PI / 180;
  const auto m = make_reduced_model(extract_samples(src, scene, eo), scene, Interpolation::CubicSpline, true);
  ReducedOptions opt;
  opt.integrator = "rk4-fixed";
  opt.fixed_step_s = h;
  opt.output_interval_s = h;
  opt.duration_s = 400 * h;
  try {
    const auto ts = simulate_reduced(m, 0.3, 12.0, opt);
    double gain = 0;  // largest kinetic-energy gain over the run, for the message
    for (size_t i = 0; i < ts.q.size(); ++i)
      gain = std::max(gain, (ts.energy[i] - offset_J) / (ts.energy[0] - offset_J));
    std::printf("h = %g s, offset %g J: no divergence reported, energy above V's zero ×%.3g\n", h, offset_J, gain);
    return NAN;
  } catch (const models::NumericalError& e) {
    const double t = std::strtod(std::strstr(e.what(), "t = ") + 4, nullptr);
    std::printf("h = %g s, offset %g J: %s\n", h, offset_J, e.what());
    return t;
  }
}

TEST(ReducedModel, DivergenceGuardDoesNotDependOnThePotentialsZero) {
  // A guard scaled by the largest |E| seen let this run gain many times its energy with exit 0
  // once V carried a large constant: the constant raised |E|, not the error. The guard's scale
  // (E0 − min V, plus the loads' work) is the same for every zero of V, so the run stops at
  // the same step whatever the offset.
  const double h = 0.08;  // 1 rad per step at 12 rad/s
  const double t0 = divergence_time(0.0, h);
  ASSERT_FALSE(std::isnan(t0));
  for (double offset : {1e3, -1e3, 1e6}) EXPECT_EQ(divergence_time(offset, h), t0) << offset;
  // ... and it does not fire on a run the step resolves (the same mechanism at 2 ms steps).
  EXPECT_TRUE(std::isnan(divergence_time(1e6, 2e-3)));
}

TEST(ReducedModel, SmallOscillationsHaveThePendulumPeriod) {
  // Constant m1 = I and V = k(1 − cos q): period 2π √(I/k) for small amplitude.
  auto scene = test::analytic_scene();
  Samples s = analytic_samples(3.0, scene);
  const double I = 0.01;
  for (auto& v : s.columns[s.require("m1")]) v = I;
  for (auto& v : s.columns[s.require("m2")]) v = 0.0;
  const auto m = make_reduced_model(s, scene, Interpolation::Fourier);
  ReducedOptions opt;
  opt.duration_s = 1.0;
  opt.output_interval_s = 1e-4;
  opt.tolerance = 1e-13;  // also an absolute tolerance: tight against a 1e-4 rad amplitude
  const auto ts = simulate_reduced(m, 1e-4, 0.0, opt);
  // First return to the start through a maximum: the period.
  double period = 0;
  for (size_t i = 2; i < ts.t.size(); ++i)
    if (ts.qdot[i - 1] > 0 && ts.qdot[i] <= 0) {
      period = ts.t[i - 1] + (ts.t[i] - ts.t[i - 1]) * ts.qdot[i - 1] / (ts.qdot[i - 1] - ts.qdot[i]);
      break;
    }
  EXPECT_NEAR(period, 2 * M_PI * std::sqrt(I / 3.0), 1e-6);
}

TEST(ReducedModel, ConstraintForceFollowsTheAlgebraicLine) {
  // F_E = me1 q̈ + me2 q̇² − Qx, with the gated torque's share along x when it is on.
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 2.0, models::RateGate{"lever", +1}});
  const auto s = analytic_samples(0.0, scene, 5);
  const auto m = make_reduced_model(s, scene, Interpolation::Fourier);
  ReducedWorkspace ws(m);
  for (double q : {0.3, 2.0, 4.0}) {
    for (double qd : {5.0, -5.0}) {
      ws.q = q, ws.qdot = qd;
      init_gates(m, ws);
      const bool on = std::cos(q) * qd > 0;  // lever rate = cos q · q̇
      EXPECT_EQ(static_cast<bool>(ws.gate_on[0]), on);
      // The production path: calc_sample (one fused lookup), as simulate_reduced's rows.
      double qdd, p, F;
      const double E = calc_sample(m, ws, q, qd, qdd, p, &F);
      double qdd_rhs, p_rhs;
      calc_acceleration(m, ws, q, qd, qdd_rhs, p_rhs);
      EXPECT_EQ(qdd, qdd_rhs);  // the same Eksergian right-hand side
      EXPECT_EQ(p, p_rhs);
      EXPECT_NEAR(p, (on ? 2.0 * std::cos(q) : 0.0) * qd, 1e-7 * std::abs(p) + 1e-9);  // torque · lever rate
      const test::SliderCrank sc0;
      EXPECT_NEAR(E, 0.5 * sc0.m1(q) * qd * qd, 1e-7 * E);  // k = 0: kinetic energy only
      const double Qx = 0.4 * std::cos(q) + (on ? 2.0 * 0.5 : 0.0);
      // The internal ≤1° resampling of the Fourier interpolant limits agreement to ~1e-8.
      EXPECT_NEAR(F, test::AnalyticSource::me1(q) * qdd + test::AnalyticSource::me2(q) * qd * qd - Qx,
                  1e-9 * std::abs(F) + 1e-7);
      // Eksergian with the gated torque through the lever ratio.
      const test::SliderCrank sc;
      EXPECT_NEAR(qdd, ((on ? 2.0 * std::cos(q) : 0.0) - sc.m2(q) * qd * qd) / sc.m1(q), 1e-7 * std::abs(qdd) + 1e-9);
    }
  }
}

TEST(ReducedModel, GatedTorqueWorkMatchesEnergyGain) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 0.05, models::RateGate{"lever", +1}});
  const auto s = analytic_samples(0.0, scene, 5);
  const auto m = make_reduced_model(s, scene, Interpolation::Fourier, true);
  ReducedOptions opt;
  opt.duration_s = 3.0;
  opt.output_interval_s = 0.01;
  opt.tolerance = 1e-12;
  const auto ts = simulate_reduced(m, 0.0, 10.0, opt);
  EXPECT_GT(ts.stats.events, 4);
  for (size_t i = 0; i < ts.t.size(); ++i)
    EXPECT_NEAR(ts.energy[i] - ts.energy[0], ts.work[i], 1e-8 * ts.energy.back());
  // Each turn the gate is on from −90° to 90° (cos q > 0 with q̇ > 0): work 2·T per turn.
  const double turns = (ts.q.back() - ts.q.front()) / (2 * M_PI);
  EXPECT_NEAR(ts.work.back(), 0.05 * 2 * turns, 0.05 * 2 * 1.01);
}

// A profiled, gated lever torque: value·τ(θ_lever(q))·r_lever in Eksergian's equation and
// value·τ·rx_lever in the constraint line, with θ_lever = sin q (analytic source).
models::JointTorque profiled(double value, double a0, double a1, std::optional<models::RateGate> gate) {
  models::LoadProfile p;
  p.of = "lever";
  p.a0 = a0;
  p.a = {a1};
  return {"drive", "lever", value, gate, p};
}

TEST(ReducedModel, ProfiledTorqueEntersEksergianAndTheConstraintLine) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back(profiled(2.0, 1.0, 0.5, models::RateGate{"lever", +1}));
  const auto s = analytic_samples(0.0, scene, 5);
  const auto m = make_reduced_model(s, scene, Interpolation::Fourier);
  ReducedWorkspace ws(m);
  const test::SliderCrank sc;
  for (double q : {0.3, 2.0, 4.0, 5.5}) {
    for (double qd : {5.0, -5.0}) {
      ws.q = q, ws.qdot = qd;
      init_gates(m, ws);
      const bool on = std::cos(q) * qd > 0;
      EXPECT_EQ(static_cast<bool>(ws.gate_on[0]), on);
      const double tau = 2.0 * (1.0 + 0.5 * std::cos(std::sin(q)));  // value·τ(θ_lever)
      double qdd, p, F;
      calc_sample(m, ws, q, qd, qdd, p, &F);  // the path simulate_reduced's outputs take
      EXPECT_NEAR(qdd, ((on ? tau * std::cos(q) : 0.0) - sc.m2(q) * qd * qd) / sc.m1(q), 1e-7 * std::abs(qdd) + 1e-9);
      EXPECT_NEAR(p, (on ? tau * std::cos(q) : 0.0) * qd, 1e-7);
      const double Qx = 0.4 * std::cos(q) + (on ? tau * 0.5 : 0.0);
      EXPECT_NEAR(F, test::AnalyticSource::me1(q) * qdd + test::AnalyticSource::me2(q) * qd * qd - Qx,
                  1e-9 * std::abs(F) + 1e-7);
      // The right-hand side's own lookup gives the same q̈.
      double qdd2, p2;
      calc_acceleration(m, ws, q, qd, qdd2, p2);
      EXPECT_NEAR(qdd2, qdd, 1e-12 * std::abs(qdd) + 1e-14);
    }
  }
}

// reduced_model_columns names what make_reduced_model reads: a model on only those columns
// (select_columns) is the model of all the samples value for value, each listed column is needed
// (the model refuses samples without it), and an unloaded joint's ratios are not listed until a
// load acts on that joint.
TEST(ReducedModel, TheColumnsItReadsGiveTheSameModel) {
  auto lever = test::analytic_scene();
  lever.joint_torques.push_back(profiled(2.0, 1.0, 0.5, models::RateGate{"lever", +1}));
  auto both = lever;
  both.joint_torques.push_back({"crank_drive", "crank", 0.3, std::nullopt, std::nullopt});
  for (const auto& scene : {lever, both}) {
    const bool crank_loaded = scene.joint_torques.size() == 2;
    const auto s = analytic_samples(0.5, scene, 10);
    const auto names = reduced_model_columns(scene);
    for (const char* crank : {"r_crank", "rx_F_crank"})
      EXPECT_EQ(std::count(names.begin(), names.end(), crank), crank_loaded ? 1 : 0) << crank;
    EXPECT_EQ(names.size() + (crank_loaded ? 0 : 2), s.names.size());
    const auto whole = make_reduced_model(s, scene, Interpolation::Fourier);
    const auto part = make_reduced_model(select_columns(s, names), scene, Interpolation::Fourier);
    EXPECT_EQ(part.table.cols, static_cast<int>(names.size()));
    ASSERT_EQ(part.gates.size(), 1u);
    EXPECT_EQ(part.gates[0].roots, whole.gates[0].roots);
    EXPECT_EQ(part.gates[0].root_sign, whole.gates[0].root_sign);
    ReducedWorkspace wa(whole), wb(part);
    for (int i = 0; i < 72; ++i)
      for (const double qd : {4.0, -4.0}) {
        const double q = 0.087 * i + 0.01;
        wa.q = wb.q = q, wa.qdot = wb.qdot = qd;
        init_gates(whole, wa), init_gates(part, wb);
        double qdd_a, p_a, F_a, qdd_b, p_b, F_b;
        const double e_a = calc_sample(whole, wa, q, qd, qdd_a, p_a, &F_a);
        const double e_b = calc_sample(part, wb, q, qd, qdd_b, p_b, &F_b);
        ASSERT_EQ(qdd_b, qdd_a) << q;
        ASSERT_EQ(p_b, p_a) << q;
        ASSERT_EQ(F_b, F_a) << q;
        ASSERT_EQ(e_b, e_a) << q;
      }
    for (const auto& name : names) {
      std::vector<std::string> fewer;
      for (const auto& n : names)
        if (n != name) fewer.push_back(n);
      EXPECT_THROW(make_reduced_model(select_columns(s, fewer), scene, Interpolation::Fourier), TableError) << name;
    }
  }
}

TEST(ReducedModel, ConstantProfileReproducesTheConstantTorque) {
  // τ(θ) ≡ a0 with amplitude 1 is the constant torque a0: the same right-hand side and
  // constraint force to round-off, and so the same motion (fixed-step RK4, so that no step-size
  // control amplifies a last-bit difference; adaptive runs agree to their tolerance).
  auto constant = test::analytic_scene(), profile = constant;
  constant.joint_torques.push_back({"drive", "lever", 0.05, models::RateGate{"lever", +1}});
  profile.joint_torques.push_back(profiled(1.0, 0.05, 0.0, models::RateGate{"lever", +1}));
  const auto ma = make_reduced_model(analytic_samples(0.0, constant, 5), constant, Interpolation::Fourier);
  const auto mb = make_reduced_model(analytic_samples(0.0, profile, 5), profile, Interpolation::Fourier);
  ReducedWorkspace wa(ma), wb(mb);
  for (int i = 0; i < 1000; ++i) {
    const double q = 0.00628 * i;
    double qa, pa, qb, pb, Fa, Fb;
    calc_sample(ma, wa, q, 3.0, qa, pa, &Fa);
    calc_sample(mb, wb, q, 3.0, qb, pb, &Fb);
    EXPECT_NEAR(qb, qa, 1e-14 * (1 + std::abs(qa))) << q;
    EXPECT_NEAR(Fb, Fa, 1e-14 * (1 + std::abs(Fa))) << q;
  }
  ReducedOptions opt;
  opt.duration_s = 3.0;
  opt.output_interval_s = 0.01;
  opt.integrator = "rk4-fixed";
  opt.fixed_step_s = 1e-3;
  const auto a = simulate_reduced(ma, 0.0, 10.0, opt);
  const auto b = simulate_reduced(mb, 0.0, 10.0, opt);
  ASSERT_EQ(a.t.size(), b.t.size());
  EXPECT_GT(b.stats.events, 4);
  for (size_t i = 0; i < a.t.size(); ++i) {
    EXPECT_NEAR(b.q[i], a.q[i], 1e-12 * (1 + std::abs(a.q[i])));
    EXPECT_NEAR(b.qdot[i], a.qdot[i], 1e-12 * std::abs(a.qdot[i]));
    EXPECT_NEAR(b.work[i], a.work[i], 1e-12 * (1 + std::abs(a.work[i])));
  }
}

// The analytic lever with a drive gated on its forward rotation and a viscous brake on the
// crank (5° fourier table): the fixed-step tests' switching model.
ReducedModel braked_gated_lever() {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 0.05, models::RateGate{"lever", +1}});
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, 1e-4});
  return make_reduced_model(analytic_samples(0.0, scene, 5), scene, Interpolation::Fourier);
}

TEST(ReducedModel, FixedStepAllocatesNothingAndTracksTheAdaptiveSolution) {
  const auto m = braked_gated_lever();
  ReducedWorkspace ws(m);
  ws.q = 0.0, ws.qdot = 10.0;
  init_gates(m, ws);
  const long before = g_allocations;
  for (int i = 0; i < 2000; ++i) step_fixed_rk4(m, ws, 1e-3);
  EXPECT_EQ(g_allocations - before, 0);
  ReducedOptions opt;
  opt.duration_s = 2.0;
  opt.output_interval_s = 0.5;
  const auto ts = simulate_reduced(m, 0.0, 10.0, opt);
  // RK4 at 1 ms with switches located by linear interpolation: ~1e-6 relative.
  EXPECT_NEAR(ws.q, ts.q.back(), 1e-5 * std::abs(ts.q.back()));
  EXPECT_NEAR(ws.qdot, ts.qdot.back(), 5e-6 * std::abs(ts.qdot.back()));
}

// simulate_reduced hands each RK4 step the derivative it already has at the step's start (the
// previous step's end point): the same steps bit for bit as computing it anew, through gate
// switches (split steps) too, and still allocation-free; calc_sample allocates nothing either.
TEST(ReducedModel, FixedStepWithKnownStartDerivativeIsTheSameStep) {
  const auto m = braked_gated_lever();
  ReducedWorkspace a(m), b(m);
  a.q = b.q = 0.0, a.qdot = b.qdot = 10.0;
  init_gates(m, a);
  init_gates(m, b);
  std::vector<double> forces(m.force_names.size());
  long switches = 0;
  const long before = g_allocations;
  for (int i = 0; i < 2000; ++i) {
    double k1[2];
    calc_acceleration(m, b, b.q, b.qdot, k1[0], k1[1]);
    const double t_a = step_fixed_rk4(m, a, 1e-3);
    step_fixed_rk4(m, b, 1e-3, k1);
    if (!std::isnan(t_a)) ++switches;
    ASSERT_EQ(a.q, b.q) << "step " << i;
    ASSERT_EQ(a.qdot, b.qdot) << "step " << i;
    ASSERT_EQ(a.work, b.work) << "step " << i;
    ASSERT_EQ(a.gate_on, b.gate_on) << "step " << i;
    double qdd, p;
    calc_sample(m, b, b.q, b.qdot, qdd, p, forces.data());
  }
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_GE(switches, 5);  // the split steps were exercised
}

// A step that stays short of the next switch angle (recorded where the gates were last
// checked) skips the prediction and the check at its end: the same steps, bit for bit, as the
// full path (the record cleared before every step), through every switch; most steps take the
// short path. A gate changed from outside at the recorded state is not trusted: the record
// holds only for the gates it was made with.
TEST(ReducedModel, FixedStepWithoutAnAngleAheadIsTheFullStep) {
  const auto m = braked_gated_lever();
  ASSERT_FALSE(m.gates.empty());
  ASSERT_FALSE(m.gates[0].roots.empty());  // predictable: the table's switch angles
  ReducedWorkspace a(m), b(m);
  a.q = b.q = 0.0, a.qdot = b.qdot = 10.0;
  init_gates(m, a);
  init_gates(m, b);
  long switches = 0, short_steps = 0;
  for (int i = 0; i < 3000; ++i) {
    const bool recorded = a.q == a.ahead_q;
    b.ahead_q = NAN;
    const double t_a = step_fixed_rk4(m, a, 2e-3);
    const double t_b = step_fixed_rk4(m, b, 2e-3);
    if (!std::isnan(t_a)) ++switches;
    if (recorded && std::isnan(t_a)) ++short_steps;
    ASSERT_EQ(std::isnan(t_a), std::isnan(t_b)) << "step " << i;
    ASSERT_EQ(a.q, b.q) << "step " << i;
    ASSERT_EQ(a.qdot, b.qdot) << "step " << i;
    ASSERT_EQ(a.work, b.work) << "step " << i;
    ASSERT_EQ(a.gate_on, b.gate_on) << "step " << i;
  }
  EXPECT_GE(switches, 5);
  EXPECT_GT(short_steps, 3000 / 2);
  // At a recorded state, the gate flipped from outside (it now disagrees with its switching
  // function): the step checks and switches it back, as the full path does.
  ASSERT_EQ(a.q, a.ahead_q);
  a.gate_on[0] = !a.gate_on[0];
  b.gate_on[0] = !b.gate_on[0];
  b.ahead_q = NAN;
  const double t_a = step_fixed_rk4(m, a, 2e-3), t_b = step_fixed_rk4(m, b, 2e-3);
  EXPECT_FALSE(std::isnan(t_a));  // the disagreement was found and switched at once
  EXPECT_EQ(std::isnan(t_a), std::isnan(t_b));
  EXPECT_EQ(a.q, b.q);
  EXPECT_EQ(a.gate_on, b.gate_on);
}

// The interpolated m1 must stay positive between the grid points: one node 40× the others
// makes the cubic spline ring below zero in the next intervals (refused, naming m1), a node 1.5×
// the others leaves it positive (accepted).
TEST(ReducedModel, RefusesAnInterpolatedInertiaThatTurnsNegativeBetweenNodes) {
  const auto scene = test::analytic_scene();
  for (double spike : {40.0, 1.5}) {
    auto s = analytic_samples(0.0, scene);
    auto& m1 = s.columns[std::find(s.names.begin(), s.names.end(), "m1") - s.names.begin()];
    const double base = *std::min_element(m1.begin(), m1.end());
    ASSERT_GT(base, 0.0);
    for (double& v : m1) v = base;
    m1[5] = spike * base;
    std::string error;
    try {
      make_reduced_model(s, scene, Interpolation::CubicSpline);
    } catch (const TableError& e) {
      error = e.what();
    }
    EXPECT_EQ(error.find("interpolated reduced inertia m1") != std::string::npos, spike > 2) << spike << ": " << error;
  }
}

TEST(ReducedModel, RefusesATableFromAnotherScene) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 2.0, models::RateGate{"lever", +1}});
  const auto s = analytic_samples(0.0, scene);
  ASSERT_TRUE(s.scene_hash);
  EXPECT_EQ(*s.scene_hash, models::scene_hash(scene));
  // Another mechanism (a heavier lever): refused, naming both fingerprints.
  auto other = scene;
  other.bodies[1].mass_kg *= 2;
  try {
    make_reduced_model(s, other, Interpolation::CubicSpline);
    ADD_FAILURE() << "a table from another scene was accepted";
  } catch (const TableError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("differ: hash " +
                       models::scene_hash_hex(*s.scene_hash) + " vs " + models::scene_hash_hex(models::scene_hash(other))),
              std::string::npos)
        << msg;
  }
  // The gate moved to another joint: the table's switch angles are not this scene's.
  auto regated = scene;
  regated.joint_torques[0].active_when->joint = "crank";
  EXPECT_THROW(make_reduced_model(s, regated, Interpolation::CubicSpline), TableError);
  // Load values are applied to the table, not stored in it (calibration scales the torque on
  // one table): accepted, and the torque is the new one.
  auto stronger = scene;
  stronger.joint_torques[0].value = 5.0;
  EXPECT_EQ(make_reduced_model(s, stronger, Interpolation::CubicSpline).torques[0].value, 5.0);
  // Samples that record no scene are refused with advice to re-extract.
  auto anonymous = s;
  anonymous.scene_hash.reset();
  try {
    make_reduced_model(anonymous, scene, Interpolation::CubicSpline);
    ADD_FAILURE() << "samples without a scene hash were accepted";
  } catch (const TableError& e) {
    EXPECT_NE(std::string(e.what()).find("re-extract"), std::string::npos) << e.what();
  }
}

// The rdyn binary end to end (status and combined output).
std::pair<int, std::string> run_rdyn(const std::string& args) {
  const std::string cmd = std::string(RDYN_BINARY) + " " + args + " 2>&1";
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

TEST(ReducedModel, CliRefusesAFourbarTableForTheBicycle) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rdyn_table_scene_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string table = (dir / "fourbar.csv").string();
  const auto [st_extract, out_extract] = run_rdyn("extract fourbar --grid-deg 30 --out " + table);
  ASSERT_EQ(st_extract, 0) << out_extract;
  const auto out = dir / "bike";
  const auto [st, msg] =
      run_rdyn("simulate bicycle --model reduced --table " + table + " --duration 0.1 --out " + out.string());
  EXPECT_EQ(st, 2) << msg;
  EXPECT_NE(msg.find("table " + table + " was extracted from a different scene ('fourbar')"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(out));
  // The same table drives the fourbar it came from.
  const auto [st_ok, msg_ok] =
      run_rdyn("simulate fourbar --model reduced --table " + table + " --duration 0.1 --out " + (dir / "fb").string());
  EXPECT_EQ(st_ok, 0) << msg_ok;
  // The same mechanism asking for reactions needs their lines: said so (was only "a different
  // scene", which sent a user who had added `reactions: all` hunting for a change in the mechanism).
  const auto [st_r, msg_r] = run_rdyn("simulate fourbar --model reduced --table " + table +
                                      " --set outputs.reactions=all --duration 0.1 --out " + (dir / "r").string());
  EXPECT_EQ(st_r, 2) << msg_r;
  EXPECT_NE(msg_r.find("table " + table + " was extracted from a different scene: it has constraint lines for rocker_axial "
                       "where scene 'fourbar' asks for rocker_axial, R_crank_gx"),
            std::string::npos)
      << msg_r;
  // Joint motion or shaking add no constraint line (the hash is the same) but need the joints'
  // columns: named with the table's file before any run (was "the reduced table has no column").
  const auto [st_j, msg_j] = run_rdyn("simulate fourbar --model reduced --table " + table +
                                      " --set outputs.shaking=true --duration 0.1 --out " + (dir / "j").string());
  EXPECT_EQ(st_j, 2) << msg_j;
  EXPECT_NE(msg_j.find("table " + table + " has no column 'p_crank'"), std::string::npos) << msg_j;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::reduced

// The switching function of a gate with exact roots: the pairwise cosine form (one cos per
// two roots) must equal the product of sines it replaces, c·Π sin((q − ρ_k)/2), which is
// computed here independently; and roots closer than 1e-3 rad keep the product itself, whose
// values near the close pair would otherwise lose digits.
TEST(ReducedModel, SwitchingPairsEqualTheProductOfSines) {
  rdyn::reduced::ReducedModel m;
  m.table.periodic = true;
  m.table.q0 = 0.0;
  m.table.period = 2 * M_PI;
  for (const std::vector<double>& roots : {std::vector<double>{0.7, 3.9}, std::vector<double>{0.2, 1.1, 2.9, 5.0},
                                           std::vector<double>{1.0, 1.0 + 4e-4}}) {
    rdyn::reduced::ReducedModel::Gate g;
    g.sign = -1;
    g.root_sign = -1.0;
    rdyn::reduced::set_gate_roots(g, roots);
    EXPECT_EQ(g.pairs.size(), roots[1] - roots[0] > 1e-3 ? roots.size() / 2 : 0u);
    m.gates = {g};
    for (double q = -20.0; q < 20.0; q += 0.0137) {
      const double qw = q - 2 * M_PI * std::floor(q / (2 * M_PI));
      double prod = -1.0;
      for (double r : roots) prod *= std::sin(0.5 * (qw - r));
      const double want = -prod * 1.7;
      EXPECT_NEAR(rdyn::reduced::calc_switching(m, 0, q, 1.7), want, 4e-15) << q;
    }
    // Just either side of each root the sign is right (1e-9 rad away).
    for (double r : roots)
      for (double d : {-1e-9, 1e-9}) {
        double prod = -1.0;
        for (double r2 : roots) prod *= std::sin(0.5 * (r + d - r2));
        EXPECT_EQ(rdyn::reduced::calc_switching(m, 0, r + d, 1.0) > 0, -prod > 0) << r << " " << d;
      }
  }
}

// A fixed step reuses the switching values of the state where the previous step ended, and
// recomputes them at any other state.
TEST(ReducedModel, SwitchingCacheFollowsTheState) {
  rdyn::reduced::ReducedModel m;
  m.table.period = 2 * M_PI;
  rdyn::reduced::ReducedModel::Gate g;
  rdyn::reduced::set_gate_roots(g, {0.5, 2.5});
  m.gates = {g};
  rdyn::reduced::ReducedWorkspace ws(m);
  const double a = rdyn::reduced::calc_switching_all(m, ws, 1.0, 2.0)[0];
  EXPECT_DOUBLE_EQ(a, rdyn::reduced::calc_switching(m, 0, 1.0, 2.0));
  const double b = rdyn::reduced::calc_switching_all(m, ws, 3.0, 2.0)[0];
  EXPECT_DOUBLE_EQ(b, rdyn::reduced::calc_switching(m, 0, 3.0, 2.0));
  EXPECT_LT(a * b, 0.0);  // 1.0 and 3.0 lie on either side of the root 2.5
  EXPECT_DOUBLE_EQ(rdyn::reduced::calc_switching_all(m, ws, 3.0, -2.0)[0], -b);
}

namespace rdyn::reduced {
namespace {

// The analytic lever with a drive torque gated on the lever's forward rotation (r_lever = cos q:
// switch angles π/2 and 3π/2, carried by the table), no brake.
ReducedModel gated_lever(double value) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", value, models::RateGate{"lever", +1}});
  return make_reduced_model(analytic_samples(0.0, scene, 5), scene, Interpolation::Fourier);
}

// A fixed step predicts the switch of a gate with known switch angles from its start derivative
// (and one right-hand side at the predicted crossing for the jerk) and cuts the step there: the
// switch time matches where the accurate solution reaches the angle (AdaptiveIntegrator stopped
// at q = π/2 to ~1e-13 s) far better than the linear estimate of the switching function between
// the step's ends, which the same model without the angle pairs falls back to; and a run over
// several switches agrees with the accurate one as closely as that fallback's run does.
TEST(ReducedModel, FixedStepPredictsTheSwitchAtItsAngle) {
  const ReducedModel m = gated_lever(0.05);
  ASSERT_EQ(m.gates.size(), 1u);
  ASSERT_EQ(m.gates[0].pairs.size(), 1u);  // predictable
  ReducedModel located = m;
  located.gates[0].pairs.clear();  // same switching function (product of sines), located after the step
  const double q0 = 1.2, v0 = 6.0, h = 0.02;
  AdaptiveIntegrator ref(m, 1e-12);
  ref.reset(0.0, q0, v0);
  ASSERT_TRUE(ref.advance(1.0, M_PI / 2));
  const double t_angle = ref.state().t;
  auto switch_time = [&](const ReducedModel& model) -> double {
    ReducedWorkspace ws(model);
    ws.q = q0, ws.qdot = v0;
    init_gates(model, ws);
    EXPECT_TRUE(ws.gate_on[0]);  // cos q > 0 while it turns forward
    for (int i = 0; i < 100; ++i) {
      const double t = step_fixed_rk4(model, ws, h);
      if (!std::isnan(t)) {
        EXPECT_FALSE(ws.gate_on[0]);
        return t;
      }
    }
    ADD_FAILURE() << "no switch within 100 steps";
    return NAN;
  };
  const double t_predicted = switch_time(m), t_located = switch_time(located);
  EXPECT_LT(std::abs(t_predicted - t_angle), 0.05 * std::abs(t_located - t_angle))
      << t_predicted << " " << t_located << " vs " << t_angle;
  // Two seconds at 5 ms steps, switching on and off every half turn.
  ReducedOptions fixed;
  fixed.duration_s = 2.0;
  fixed.output_interval_s = 0.25;
  fixed.integrator = "rk4-fixed";
  fixed.fixed_step_s = 0.005;
  ReducedOptions accurate = fixed;
  accurate.integrator = "rk8pd";
  accurate.tolerance = 1e-12;
  const auto ref_run = simulate_reduced(m, q0, v0, accurate);
  auto worst = [&](const models::TimeSeries& a) {
    EXPECT_EQ(a.t.size(), ref_run.t.size());
    double e = 0;
    for (size_t i = 0; i < a.t.size() && i < ref_run.t.size(); ++i)
      e = std::max(e, std::abs(a.qdot[i] - ref_run.qdot[i]) / std::abs(ref_run.qdot[i]));
    return e;
  };
  const auto a = simulate_reduced(m, q0, v0, fixed), b = simulate_reduced(located, q0, v0, fixed);
  EXPECT_GE(a.stats.events, 6);
  EXPECT_EQ(a.stats.events, b.stats.events);
  EXPECT_LT(worst(a), 3e-3);  // RK4 at 5 ms on this lever: 1.6e-3
  EXPECT_LT(worst(a), 1.1 * worst(b));
}

// A gate open over less than one step is still applied: both switches are predicted inside the
// step, so the drive does its work T·∫ r dq = T·(sin 1.1 − sin 1.0) over the open arc [1.0, 1.1]
// (r = cos q). Located only after the step, the gate agrees with its switching function at both
// ends (closed) and the load would be missed.
TEST(ReducedModel, FixedStepAppliesAGateOpenForLessThanAStep) {
  const double T = 0.8;
  ReducedModel m = gated_lever(T);
  set_gate_roots(m.gates[0], {1.0, 1.1});
  m.gates[0].root_sign = -1.0;  // on between the angles while q̇ > 0
  ReducedWorkspace ws(m);
  ws.q = 0.8, ws.qdot = 8.0;
  init_gates(m, ws);
  ASSERT_FALSE(ws.gate_on[0]);
  const double t_switch = step_fixed_rk4(m, ws, 0.05);  // q passes 0.8 → ~1.2
  ASSERT_GT(ws.q, 1.15);
  EXPECT_FALSE(std::isnan(t_switch));
  EXPECT_FALSE(ws.gate_on[0]);
  // Each switch lands within O(τ⁴) of its angle: here (τ ≈ 26 ms, q̈ ≈ −30 rad/s²) 2.6e-4 rad
  // at 1.0 and 2e-5 rad at 1.1, 0.3 % of the work.
  const double want = T * (std::sin(1.1) - std::sin(1.0));
  EXPECT_NEAR(ws.work, want, 0.01 * want);
}

// A predicted switch stands only where the step reached its angle: with the angle placed just
// beyond where the step really ends (q1 + ε), no switch is made or reported, whatever the Taylor
// path predicted; with it just inside (q1 − ε), the switch is made.
TEST(ReducedModel, FixedStepSwitchesOnlyWhereTheStepReachesTheAngle) {
  ReducedModel m = gated_lever(0.05);
  const double q0 = 1.0, v0 = 6.0, h = 0.03;
  set_gate_roots(m.gates[0], {3.0, 5.0});  // far away: the free step's end
  ReducedWorkspace free(m);
  free.q = q0, free.qdot = v0;
  init_gates(m, free);
  step_fixed_rk4(m, free, h);
  const double q1 = free.q;
  for (double eps : {1e-7, 1e-6, 1e-5, 1e-4, 1e-3}) {
    for (double side : {+1.0, -1.0}) {
      ReducedModel g = m;
      set_gate_roots(g.gates[0], {q1 + side * eps, 5.0});
      ReducedWorkspace ws(g);
      ws.q = q0, ws.qdot = v0;
      init_gates(g, ws);
      const bool before = ws.gate_on[0];
      const double t = step_fixed_rk4(g, ws, h);
      const bool reached = side < 0;
      EXPECT_EQ(std::isnan(t), !reached) << eps << " " << side;
      EXPECT_EQ(static_cast<bool>(ws.gate_on[0]), reached ? !before : before) << eps << " " << side;
    }
  }
}

// Prediction needs every gate's angles: with one gate without them (its pairs cleared), a cut at
// the other's predicted switch would pass over this one's switch before it. Such a model takes
// the check at the step's end for all its gates: the same steps as with no angle pairs at all
// (to rounding: the paired switching function is the product of sines written differently). Roots far outside a turn (a hand-made table) are no angles either (and no
// undefined cast: UBSan in CI).
TEST(ReducedModel, FixedStepPredictsOnlyWhenEveryGateHasItsAngles) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"a", "lever", 0.01, models::RateGate{"lever", +1}});
  scene.joint_torques.push_back({"b", "lever", 0.03, models::RateGate{"lever", +1}});
  ReducedModel mixed = make_reduced_model(analytic_samples(0.0, scene, 5), scene, Interpolation::Fourier);
  ASSERT_EQ(mixed.gates.size(), 2u);
  set_gate_roots(mixed.gates[0], {1.65, 4.0});
  set_gate_roots(mixed.gates[1], {1.64, 4.5});
  mixed.gates[1].pairs.clear();
  ReducedModel none = mixed;
  none.gates[0].pairs.clear();
  ReducedWorkspace a(mixed), b(none);
  a.q = b.q = 1.5, a.qdot = b.qdot = 6.0;
  init_gates(mixed, a);
  init_gates(none, b);
  int switches = 0;
  for (int i = 0; i < 300; ++i) {
    const double ta = step_fixed_rk4(mixed, a, 0.01), tb = step_fixed_rk4(none, b, 0.01);
    switches += !std::isnan(ta);
    ASSERT_NEAR(a.q, b.q, 1e-12 * std::abs(b.q)) << i;
    ASSERT_NEAR(a.qdot, b.qdot, 1e-12 * std::abs(b.qdot)) << i;
    ASSERT_EQ(a.gate_on, b.gate_on) << i;
    ASSERT_EQ(std::isnan(ta), std::isnan(tb)) << i;
  }
  EXPECT_GE(switches, 4);
  ReducedModel far = gated_lever(0.05);
  set_gate_roots(far.gates[0], {0.5, 1e20});
  ASSERT_EQ(far.gates[0].pairs.size(), 1u);
  ReducedWorkspace w(far);
  w.q = 1.0, w.qdot = 6.0;
  init_gates(far, w);
  for (int i = 0; i < 50; ++i) step_fixed_rk4(far, w, 0.02);
  EXPECT_TRUE(std::isfinite(w.q) && std::isfinite(w.qdot) && std::isfinite(w.work));
}

}  // namespace
}  // namespace rdyn::reduced
