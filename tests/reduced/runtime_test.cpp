// The embedding runtime: the same trajectory as the simulator's fixed-step path, drive
// commands, argument checks that leave the state alone, no allocation, tables checked
// against their scene.
#include "reduced/runtime.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <tuple>

#include "analytic_source.hpp"
#include "cli_table.hpp"
#include "count_allocations.hpp"
#include "models/scene_yaml.hpp"
#include "pendulum_table.hpp"
#include "reduced/extract.hpp"
#include "reduced/simulate_reduced.hpp"

namespace rdyn::reduced {
namespace {

// The analytic slider-crank with every kind of load the runtime must carry: a drive torque on
// the lever gated by the lever's rate (it switches twice a turn), a viscous brake on the crank,
// and the constraint force F.
models::Scene driven_scene(double torque) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", torque, models::RateGate{"lever", +1}});
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, 1e-4});
  return scene;
}

Samples analytic_samples(const models::Scene& scene) {
  test::AnalyticSource src;
  src.k = 0.01;
  ExtractOptions opt;
  opt.step_rad = 5 * M_PI / 180;
  return extract_samples(src, scene, opt);
}

RuntimeModel driven_model(double torque) {
  const auto scene = driven_scene(torque);
  return make_runtime_model(analytic_samples(scene), scene, {Interpolation::CubicSpline});
}

// Absolute-plus-relative closeness.
void expect_close(double a, double b, double tol, const char* what, int step) {
  EXPECT_NEAR(a, b, tol * (1.0 + std::abs(b))) << what << " at step " << step;
}

// Runs n steps of dt with a fixed drive and compares every step with rdyn's simulator on the
// fixed-step path (rk4-fixed, outputs at every step) for `reference`.
void expect_matches_simulator(const RuntimeModel& model, const Drive& drive,
                              const ReducedModel& reference, double q0, double qdot0) {
  const double dt = 1e-3;
  const int n = 2000;
  ReducedOptions opt;
  opt.integrator = "rk4-fixed";
  opt.fixed_step_s = dt;
  opt.output_interval_s = dt;
  opt.duration_s = n * dt;
  const auto ts = simulate_reduced(reference, q0, qdot0, opt);
  ASSERT_EQ(ts.t.size(), static_cast<size_t>(n + 1));
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, q0, qdot0, drive), Status::Ok);
  // Both start from the same outputs (gates set from the same state).
  expect_close(ws.get_qddot(), ts.qddot[0], 1e-12, "q̈", 0);
  for (int i = 1; i <= n; ++i) {
    ASSERT_EQ(step(model, ws, dt, drive), Status::Ok) << "step " << i;
    // The simulator's outputs are its step ends read through its quintic Hermite interpolant
    // at the output times i·dt, which differ from the summed step times by ~1e-13 s (so q by
    // ~1e-13 s × 35 rad/s); q̇ there is a difference of q values (~20 rad, ulp 4e-15) over the
    // 1 ms step, so it carries ~1e-10 rad/s of rounding. Any other integrator or step split
    // would differ by RK4's own error, ~1e-6. q̈ and F are then recomputed from (q, q̇), where
    // m1, m2 change fast near the slider-crank's dead points and amplify that rounding to
    // ~1e-7; what they check is the loads in them: a gate or drive torque taken wrongly
    // changes q̈ by T·r/m1 ≈ 0.05/0.01 = O(1).
    expect_close(ws.get_t(), ts.t[i], 1e-13, "t", i);
    expect_close(ws.get_q(), ts.q[i], 1e-12, "q", i);
    expect_close(ws.get_qdot(), ts.qdot[i], 1e-11, "q̇", i);
    expect_close(ws.get_qddot(), ts.qddot[i], 1e-6, "q̈", i);
    expect_close(ws.get_work(), ts.work[i], 1e-12, "W", i);
    expect_close(ws.get_energy(), ts.energy[i], 1e-11, "E", i);
    expect_close(ws.get_forces()[0], ts.forces[0][i], 1e-6, "F", i);
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(ws.get_switches(), 4);  // the gated torque switched: the split steps were compared too
  EXPECT_GT(std::abs(ws.get_q() - q0), 1.0);  // it moved (a braking drive turns it back)
}

TEST(Runtime, StepFollowsTheSimulatorsFixedStepPath) {
  const auto model = driven_model(0.05);
  expect_matches_simulator(model, Drive::scaled(1.0), model.reduced, 0.3, 10.0);
}

TEST(Runtime, DriveScalesOrSetsTheSceneTorques) {
  // Load values are not part of the table: a scene with three times the torque runs on the
  // same samples, and a drive of ×3 (or of |T| = 0.15 with the scene's sign) must reproduce it.
  for (double sign : {1.0, -1.0}) {
    const auto model = driven_model(sign * 0.05);
    const auto stronger = driven_scene(sign * 0.15);
    const auto reference =
        make_reduced_model(analytic_samples(stronger), stronger, Interpolation::CubicSpline);
    SCOPED_TRACE(sign > 0 ? "positive torque" : "negative torque");
    expect_matches_simulator(model, Drive::scaled(3.0), reference, 0.3, 10.0);
    expect_matches_simulator(model, Drive::torque(0.15), reference, 0.3, 10.0);
    RuntimeWorkspace ws(model);
    ASSERT_EQ(step(model, ws, 1e-3, Drive::torque(0.15)), Status::Ok);
    EXPECT_EQ(ws.get_drive_torques()[0], sign * 0.15);
  }
  // And the command matters: ×3 is not the scene's own run.
  const auto model = driven_model(0.05);
  RuntimeWorkspace a(model), b(model);
  for (int i = 0; i < 1000; ++i) {
    step(model, a, 1e-3, Drive::scaled(1.0));
    step(model, b, 1e-3, Drive::scaled(3.0));
  }
  EXPECT_GT(b.get_work(),
            2.5 * a.get_work() - 1e-12);  // the drive does ~3× the work (minus the brake's)
}

TEST(Runtime, EveryStepAdvancesTimeEvenWhenAGateChatters) {
  // A negative torque gated on the lever's positive rate brakes the lever whenever it is on,
  // which drives its own switching function back through zero: the gate chatters (sliding).
  // The split steps must still add up to dt.
  const auto model = driven_model(-0.15);
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, 0.3, 10.0), Status::Ok);
  for (int i = 1; i <= 3000; ++i) {
    ASSERT_EQ(step(model, ws, 1e-3, Drive{}), Status::Ok);
    ASSERT_NEAR(ws.get_t(), i * 1e-3, 1e-12) << "step " << i;
  }
  EXPECT_GT(ws.get_switches(), 4);
}

TEST(Runtime, WorkspaceStartsAtTheScenesInitialState) {
  auto scene = driven_scene(0.05);
  scene.initial.q = 0.7;
  scene.initial.qdot = 4.0;
  const auto model = make_runtime_model(analytic_samples(scene), scene, {});
  const RuntimeWorkspace ws(model);
  EXPECT_EQ(ws.get_t(), 0.0);
  EXPECT_EQ(ws.get_q(), 0.7);
  EXPECT_EQ(ws.get_qdot(), 4.0);
  EXPECT_EQ(model.drive_names, std::vector<std::string>{"drive"});
  EXPECT_EQ(model.drive_nominal, std::vector<double>{0.05});
  // q̈ from Eksergian at that state (the lever's rate cos q · q̇ > 0: the torque is on).
  const test::SliderCrank sc;
  const double expected =
      (-0.01 * std::sin(0.7) + 0.05 * std::cos(0.7) - 1e-4 * 4.0 - sc.m2(0.7) * 16.0) / sc.m1(0.7);
  EXPECT_NEAR(ws.get_qddot(), expected, 1e-6 * std::abs(expected));
}

TEST(Runtime, ResetAndStepAllocateNothing) {
  const auto model = driven_model(0.05);
  RuntimeWorkspace ws(model);
  const long before = g_allocations;
  ASSERT_EQ(reset(model, ws, 0.0, 10.0), Status::Ok);
  for (int i = 0; i < 3000; ++i) {
    const Status s = step(model, ws, 1e-3, Drive::torque(0.05 + 0.01 * std::sin(i * 1e-2)));
    if (s != Status::Ok) FAIL() << status_message(s);
  }
  step(model, ws, NAN, Drive{});  // refusals allocate nothing either
  step(model, ws, 1e-3, Drive::scaled(INFINITY));
  EXPECT_EQ(g_allocations - before, 0);
  EXPECT_GT(ws.get_switches(), 4);
}

// Everything a caller can read, to check that a refused call changed nothing.
std::vector<double> snapshot(const RuntimeWorkspace& ws) {
  std::vector<double> v{ws.get_t(),     ws.get_q(),    ws.get_qdot(),
                        ws.get_qddot(), ws.get_work(), ws.get_energy()};
  v.insert(v.end(), ws.get_forces().begin(), ws.get_forces().end());
  v.insert(v.end(), ws.get_drive_torques().begin(), ws.get_drive_torques().end());
  for (char g : ws.get_state().gate_on) v.push_back(g);
  return v;
}

TEST(Runtime, BadArgumentsAreRefusedAndChangeNothing) {
  const auto model = driven_model(0.05);
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, 0.3, 10.0, Drive::scaled(2.0)), Status::Ok);
  for (int i = 0; i < 10; ++i) ASSERT_EQ(step(model, ws, 1e-3, Drive::scaled(2.0)), Status::Ok);
  const auto before = snapshot(ws);
  // Steps outside [1e-7, 1] s (the simulator's fixed-step range).
  for (double dt : std::initializer_list<double>{NAN, INFINITY, -1e-3, 0.0, 9e-8, 1.5}) {
    EXPECT_EQ(step(model, ws, dt, Drive{}), Status::BadStep) << dt;
    EXPECT_EQ(snapshot(ws), before) << dt;
  }
  EXPECT_EQ(step(model, ws, 1e-7, Drive::scaled(2.0)),
            Status::Ok);  // the bounds themselves are valid
  const auto after_min_step = snapshot(ws);
  // Drives that are not finite or command more than 1e6 N·m (models::limits::kMaxForce).
  for (const Drive& d : {Drive::scaled(NAN), Drive::scaled(-INFINITY), Drive::torque(NAN),
                         Drive::torque(1.5e6), Drive::torque(-1.5e6), Drive::scaled(2.1e7)}) {
    EXPECT_EQ(step(model, ws, 1e-3, d), Status::BadDrive) << d.value;
    EXPECT_EQ(snapshot(ws), after_min_step) << d.value;
  }
  EXPECT_EQ(reset(model, ws, 0.3, 10.0, Drive::torque(1.5e6)), Status::BadDrive);
  // Each refusal names its one cause (one message once covered all three).
  EXPECT_NE(std::string(ws.describe(Status::BadDrive)).find("exceeds 1e6"), std::string::npos);
  EXPECT_EQ(step(model, ws, 1e-3, Drive::torque(NAN)), Status::BadDrive);
  EXPECT_NE(std::string(ws.describe(Status::BadDrive)).find("not finite"), std::string::npos);
  EXPECT_STREQ(ws.describe(Status::BadStep), status_message(Status::BadStep));
  // States that are not finite or out of range (|q̇| ≤ 1e4, models::limits::kMaxRate).
  for (auto [q, qd] : std::initializer_list<std::pair<double, double>>{
           {NAN, 1.0}, {0.0, INFINITY}, {0.0, 1.1e4}, {2e6, 0.0}}) {
    EXPECT_EQ(reset(model, ws, q, qd), Status::BadState) << q << " " << qd;
    EXPECT_EQ(snapshot(ws), after_min_step);
  }
  EXPECT_EQ(reset(model, ws, 0.0, 1.1e4), Status::BadState);
  EXPECT_STREQ(ws.describe(Status::BadState), "|q̇| exceeds 1e4 rad/s (m/s)");
  EXPECT_EQ(reset(model, ws, NAN, 0.0), Status::BadState);
  EXPECT_STREQ(ws.describe(Status::BadState), "the state is not finite");
  EXPECT_EQ(reset(model, ws, 0.0, -1e4), Status::Ok);
}

// A scene without joint torques has nothing a drive commands: a torque or a scale other than
// 1 is refused (was ignored, so a controller ran open loop without knowing); the scene's own
// drive steps.
TEST(Runtime, ADriveForASceneWithoutJointTorquesIsRefused) {
  auto scene = test::analytic_scene();
  scene.resistances.push_back({"brake", "crank", models::ResistanceLaw::Viscous, 1e-4});
  ASSERT_TRUE(scene.joint_torques.empty());
  const auto model = make_runtime_model(analytic_samples(scene), scene, {Interpolation::CubicSpline});
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, 0.3, 10.0), Status::Ok);
  const auto before = snapshot(ws);
  for (const Drive& d : {Drive::torque(5.0), Drive::torque(0.0), Drive::scaled(2.0)}) {
    EXPECT_EQ(step(model, ws, 1e-3, d), Status::BadDrive) << d.value;
    EXPECT_EQ(snapshot(ws), before);
  }
  EXPECT_EQ(reset(model, ws, 0.3, 10.0, Drive::torque(5.0)), Status::BadDrive);
  EXPECT_EQ(step(model, ws, 1e-3, Drive{}), Status::Ok);
  EXPECT_NE(std::string(ws.describe(Status::BadDrive)).find("no joint torque"), std::string::npos);
  EXPECT_EQ(std::string(ws.describe(Status::BadDrive)).find("not finite"), std::string::npos);
}

TEST(Runtime, AWorkspaceOfAnotherModelIsRefused) {
  const auto model = driven_model(0.05);
  auto plain_scene = test::analytic_scene();  // no torque, no brake: other sizes
  const auto plain = make_runtime_model(analytic_samples(plain_scene), plain_scene, {});
  RuntimeWorkspace ws(plain);
  EXPECT_EQ(step(model, ws, 1e-3, Drive{}), Status::WrongWorkspace);
  EXPECT_EQ(reset(model, ws, 0.0, 1.0), Status::WrongWorkspace);
  EXPECT_EQ(step(plain, ws, 1e-3, Drive{}), Status::Ok);
}

TEST(Runtime, NonFiniteStepIsReportedAndRolledBack) {
  // m2 = 1e300: q̈ = −m2 q̇²/m1 is finite at q̇ = 1 but the state overflows within a step.
  const auto scene = driven_scene(0.05);
  auto s = analytic_samples(scene);
  for (auto& v : s.columns[s.require("m2")]) v = 1e300;
  const auto model = make_runtime_model(s, scene, {Interpolation::Linear});
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, 0.2, 1.0), Status::Ok);
  const auto before = snapshot(ws);
  EXPECT_EQ(step(model, ws, 1e-3, Drive{}), Status::NonFinite);
  EXPECT_EQ(snapshot(ws), before);                           // rolled back: never a NaN to read
  EXPECT_EQ(reset(model, ws, 0.2, 1e4), Status::NonFinite);  // q̈ overflows at once
  EXPECT_EQ(snapshot(ws), before);
}

TEST(Runtime, LeavingANonPeriodicTableIsReported) {
  // The same samples read as a non-periodic table over [0°, 355°].
  const auto scene = driven_scene(0.05);
  auto s = analytic_samples(scene);
  s.periodic = false;
  const auto model = make_runtime_model(s, scene, {});  // cubic spline: Fourier needs a period
  RuntimeWorkspace ws(model);
  EXPECT_EQ(reset(model, ws, -0.1, 0.0), Status::BadState);
  ASSERT_EQ(reset(model, ws, 6.0, 5.0), Status::Ok);
  Status st = Status::Ok;
  int steps = 0;
  while (st == Status::Ok && steps < 1000) st = step(model, ws, 1e-3, Drive{}), ++steps;
  EXPECT_EQ(st, Status::LeftTable);
  EXPECT_LT(steps, 100);  // 355° − 6 rad ≈ 0.2 rad at 5 rad/s: ~40 steps
  EXPECT_TRUE(model.reduced.table.in_range(ws.get_q()));  // the last valid state is kept
  EXPECT_GT(ws.get_q(), 6.0);
}

TEST(Runtime, DivergenceIsReported) {
  // One-second RK4 steps at 40 rad/s cover six turns of a mechanism whose inertia varies
  // three-fold within a turn: the energy balance breaks, and the step is refused.
  const auto model = driven_model(0.05);
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, 0.0, 40.0), Status::Ok);
  Status st = Status::Ok;
  for (int i = 0; i < 20 && st == Status::Ok; ++i) st = step(model, ws, 1.0, Drive{});
  EXPECT_EQ(st, Status::Diverged);
  for (double v : snapshot(ws)) EXPECT_TRUE(std::isfinite(v));
}

// calc_drive_torque against Eksergian's equation written out for the analytic slider-crank:
// drive = m1 q̈ + m2 q̇² − F*, F* = −k sin q (potential) + T·cos q (the lever's torque, on while
// the lever's rate cos q · q̇ > 0) − c q̇ (the brake on the crank).
TEST(Runtime, DriveTorqueIsEksergianSolvedForTheDrive) {
  const auto model = driven_model(0.05);
  RuntimeWorkspace ws(model);
  const test::SliderCrank sc;
  auto closed_form = [&](double q, double qd, double qdd, double T) {
    const bool on = std::cos(q) * qd > 0;
    return sc.m1(q) * qdd + sc.m2(q) * qd * qd + 0.01 * std::sin(q) - (on ? T * std::cos(q) : 0.0) + 1e-4 * qd;
  };
  const auto before = snapshot(ws);
  for (double q : {0.1, 1.0, 2.0, 3.5, 5.0})
    for (double qd : {-7.0, 0.5, 12.0})
      for (double qdd : {-30.0, 0.0, 4.0}) {
        double d = NAN;
        ASSERT_EQ(calc_drive_torque(model, ws, q, qd, qdd, d), Status::Ok);
        // 5° cubic-spline table: its interpolation error in m1, m2 (~1e-6 relative).
        const double want = closed_form(q, qd, qdd, 0.05);
        EXPECT_NEAR(d, want, 2e-5 * (1 + std::abs(want)) + 1e-5 * sc.m1(q) * std::abs(qdd)) << q << " " << qd << " " << qdd;
      }
  EXPECT_EQ(snapshot(ws), before);  // the state and its gates untouched
  // The joint torques as last commanded: after a step at T = 0.2 the lever's share changes.
  ASSERT_EQ(step(model, ws, 1e-3, Drive::torque(0.2)), Status::Ok);
  double d05 = NAN, d2 = NAN;
  RuntimeWorkspace fresh(model);
  ASSERT_EQ(calc_drive_torque(model, fresh, 0.4, 3.0, 1.0, d05), Status::Ok);
  ASSERT_EQ(calc_drive_torque(model, ws, 0.4, 3.0, 1.0, d2), Status::Ok);
  // The lever's ratio cos q from the 5° cubic-spline table (~1e-7 relative).
  EXPECT_NEAR(d05 - d2, (0.2 - 0.05) * std::cos(0.4), 1e-6 * 0.15);
}

// Two routes: the forward step's own acceleration needs no drive beyond the commanded torques,
// at every state of a run through the gate switches.
TEST(Runtime, DriveTorqueOfTheModelsOwnAccelerationIsZero) {
  const auto model = driven_model(0.05);
  RuntimeWorkspace ws(model);
  ASSERT_EQ(reset(model, ws, 0.0, 10.0, Drive::torque(0.08)), Status::Ok);
  const long before = g_allocations;
  double worst = 0.0;
  for (int i = 0; i < 2000; ++i) {
    ASSERT_EQ(step(model, ws, 1e-3, Drive::torque(0.08)), Status::Ok);
    double d = NAN;
    ASSERT_EQ(calc_drive_torque(model, ws, ws.get_q(), ws.get_qdot(), ws.get_qddot(), d), Status::Ok);
    worst = std::max(worst, std::abs(d));
  }
  EXPECT_EQ(g_allocations - before, 0);  // allocation-free
  EXPECT_LT(worst, 1e-12);               // [N·m]; the torques themselves are 0.08
  EXPECT_GT(ws.get_switches(), 4);
}

TEST(Runtime, DriveTorqueRefusesBadStatesAndLeavesTheResult) {
  const auto model = driven_model(0.05);
  RuntimeWorkspace ws(model);
  for (auto [q, qd, qdd] : std::initializer_list<std::tuple<double, double, double>>{
           {NAN, 1.0, 0.0}, {0.0, INFINITY, 0.0}, {0.0, 1.0, NAN}, {0.0, 1.1e4, 0.0}, {0.0, 1.0, 2e8}, {2e6, 0.0, 0.0}}) {
    double d = -3.0;
    EXPECT_EQ(calc_drive_torque(model, ws, q, qd, qdd, d), Status::BadState) << q << " " << qd << " " << qdd;
    EXPECT_EQ(d, -3.0);
  }
  auto s = analytic_samples(driven_scene(0.05));
  s.periodic = false;
  const auto ranged = make_runtime_model(s, driven_scene(0.05), {});
  RuntimeWorkspace rws(ranged);
  double d = 0.0;
  EXPECT_EQ(calc_drive_torque(ranged, rws, -0.1, 1.0, 0.0, d), Status::BadState);  // outside [0°, 355°]
  auto plain_scene = test::analytic_scene();
  const auto plain = make_runtime_model(analytic_samples(plain_scene), plain_scene, {});
  RuntimeWorkspace pws(plain);
  EXPECT_EQ(calc_drive_torque(model, pws, 0.0, 1.0, 0.0, d), Status::WrongWorkspace);
}

TEST(Runtime, StatusMessagesExistForEveryStatus) {
  for (int s = 0; s <= static_cast<int>(Status::Diverged); ++s)
    EXPECT_STRNE(status_message(static_cast<Status>(s)), "unknown status") << s;
  EXPECT_STREQ(status_message(static_cast<Status>(99)), "unknown status");
}

TEST(Runtime, LoadsATableFileCheckedAgainstItsScene) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rdyn_runtime_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string table = (dir / "fourbar.csv").string();
  ASSERT_EQ(test::extract_table_with_cli("fourbar", "30", table), 0);
  // Its own scene: loaded, at the scene's initial state (fourbar.yaml: 30°, 8 rad/s).
  const auto model = load_runtime_model(table, "fourbar");
  EXPECT_EQ(model.scene_name, "fourbar");
  EXPECT_NEAR(model.initial_q, 30 * M_PI / 180, 1e-15);
  EXPECT_EQ(model.initial_qdot, 8.0);
  EXPECT_EQ(model.reduced.force_names, std::vector<std::string>{"rocker_axial"});
  RuntimeWorkspace ws(model);
  EXPECT_EQ(ws.get_qdot(), 8.0);
  for (int i = 0; i < 100; ++i) ASSERT_EQ(step(model, ws, 1e-3, Drive{}), Status::Ok);
  EXPECT_GT(ws.get_q(), model.initial_q + 0.05);  // it turned (gravity slows it: no full turn)
  EXPECT_NEAR(ws.get_t(), 0.1, 1e-12);
  // Another scene: refused before anything runs.
  try {
    load_runtime_model(table, "bicycle");
    ADD_FAILURE() << "a fourbar table was accepted for the bicycle";
  } catch (const TableError& e) {
    EXPECT_NE(
        std::string(e.what()).find("table " + table + " was extracted from a different scene"),
        std::string::npos)
        << e.what();
  }
  EXPECT_THROW(load_runtime_model((dir / "missing.csv").string(), "fourbar"), TableError);
  EXPECT_THROW(load_runtime_model(table, "no-such-scene"), models::SceneError);
  fs::remove_all(dir);
}

// The pendulum's pivot reaction in closed form, R = m (a_c − g) with a_c the centre of mass's
// acceleration: hanging (q = −90°) at ω, a_c = l ω² up, so R = (0, m (g + l ω²)); horizontal
// (q = 0) at ω, a_c = (−l ω², l α) with α = −m g l / I_O (I_O = I + m l²), so R = (−m l ω²,
// m (g + l α)). The shaking load on the ground is −R, and the joint's own motion is the state.
TEST(Runtime, PendulumPivotReactionIsItsClosedForm) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rdyn_runtime_pendulum_" + std::to_string(::getpid()));
  ASSERT_EQ(test::write_pendulum_table(dir), 0);
  const auto model = load_runtime_model((dir / "pendulum.csv").string(), (dir / "pendulum.yaml").string());
  fs::remove_all(dir);
  ASSERT_TRUE(model.joint_outputs.has_value());
  EXPECT_EQ(model.joint_outputs->names,
            (std::vector<std::string>{"q_pivot", "qdot_pivot", "qddot_pivot", "R_pivot_x", "R_pivot_y", "shaking_x",
                                      "shaking_y", "shaking_M"}));
  EXPECT_TRUE(model.force_names.empty());  // the reaction lines are the model's own
  RuntimeWorkspace ws(model);
  EXPECT_TRUE(ws.get_forces().empty());
  const double m = test::kPendulumMass_kg, l = test::kPendulumArm_m, g = 9.81, w = 3.0;
  const double I_O = test::kPendulumInertia_kgm2 + m * l * l, alpha = -m * g * l / I_O;
  struct Case {
    double q, Rx, Ry, qddot;
  };
  for (const Case& c : {Case{-M_PI / 2, 0.0, m * (g + l * w * w), 0.0}, Case{0.0, -m * l * w * w, m * (g + l * alpha), alpha}}) {
    ASSERT_EQ(reset(model, ws, c.q, w), Status::Ok);
    const auto& o = ws.get_joint_outputs();
    ASSERT_EQ(o.size(), 8u);
    const double scale = m * (g + l * w * w);  // the largest reaction component here [N]
    EXPECT_NEAR(o[0], c.q, 1e-12);
    EXPECT_NEAR(o[1], w, 1e-12);
    EXPECT_NEAR(o[2], c.qddot, 1e-9 * std::abs(alpha));
    EXPECT_NEAR(o[3], c.Rx, 1e-9 * scale) << "at q = " << c.q;
    EXPECT_NEAR(o[4], c.Ry, 1e-9 * scale) << "at q = " << c.q;
    EXPECT_NEAR(o[5], -o[3], 1e-9 * scale);
    EXPECT_NEAR(o[6], -o[4], 1e-9 * scale);
  }
}

// A row of timeseries.csv by column name.
std::map<std::string, std::vector<double>> read_columns(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string f; std::getline(hs, f, ',');) names.push_back(f);
  std::map<std::string, std::vector<double>> c;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    size_t k = 0;
    for (std::string f; std::getline(ls, f, ',') && k < names.size(); ++k) c[names[k]].push_back(std::stod(f));
  }
  return c;
}

// The runtime takes the table `rdyn extract` writes for a scene that asks for joint outputs (it
// used to refuse it as "extracted from a different scene") and gives, at every state of a
// `rdyn simulate --model reduced` run, that row's joint outputs and constraint force: the
// slider-crank with every joint's motion and reaction (revolute, prismatic, the wrist-pin loop;
// `reactions: all`) and the shaking load, reset to each row's (q, q̇), to 1e-9 of each column's
// peak. Reset and step allocate nothing with the joint outputs either.
TEST(Runtime, JointOutputsAreTheReducedRunsRows) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rdyn_runtime_joints_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::vector<std::string> sets{"--set", "outputs.reactions=all", "--set", "outputs.shaking=true",
                                      "--set", "outputs.joints=all"};
  const std::string table = (dir / "slider-crank.csv").string();
  std::vector<std::string> extract{"extract", "slider-crank", "--out", table};
  extract.insert(extract.end(), sets.begin(), sets.end());
  ASSERT_EQ(test::run_rdyn_cli(extract), 0);
  std::vector<std::string> simulate{"simulate", "slider-crank", "--model", "reduced", "--table", table,
                                    "--duration", "0.3", "--out", (dir / "run").string()};
  simulate.insert(simulate.end(), sets.begin(), sets.end());
  ASSERT_EQ(test::run_rdyn_cli(simulate), 0);
  auto rows = read_columns(dir / "run" / "timeseries.csv");
  const auto scene = models::load_scene(
      "slider-crank", {{"outputs.reactions", "all"}, {"outputs.shaking", "true"}, {"outputs.joints", "all"}});
  const auto model = make_runtime_model(read_samples_csv(table), scene);
  fs::remove_all(dir);
  ASSERT_TRUE(model.joint_outputs.has_value());
  const auto& names = model.joint_outputs->names;
  ASSERT_EQ(names.size(), 3u * 3 + 2 + 2 + 4 + 2 + 3);  // motions; crank, rod, slider (prismatic), wrist_pin; shaking
  EXPECT_EQ(model.force_names, std::vector<std::string>{"rod_axial"});
  RuntimeWorkspace ws(model);
  ASSERT_GT(rows["t"].size(), 100u);
  std::vector<std::string> compared = names;
  compared.push_back("F_rod_axial");
  std::map<std::string, double> peak;
  for (const auto& n : compared) {
    ASSERT_EQ(rows[n].size(), rows["t"].size()) << n;
    for (double v : rows[n]) peak[n] = std::max(peak[n], std::abs(v));
  }
  for (size_t i = 0; i < rows["t"].size(); ++i) {
    ASSERT_EQ(reset(model, ws, rows["q"][i], rows["qdot"][i]), Status::Ok);
    for (size_t c = 0; c < names.size(); ++c)
      ASSERT_NEAR(ws.get_joint_outputs()[c], rows[names[c]][i], 1e-9 * std::max(peak[names[c]], 1e-9))
          << names[c] << " at row " << i;
    ASSERT_NEAR(ws.get_forces()[0], rows["F_rod_axial"][i], 1e-9 * peak["F_rod_axial"]) << i;
  }
  const long before = g_allocations;
  ASSERT_EQ(reset(model, ws, scene.initial.q, scene.initial.qdot), Status::Ok);
  for (int i = 0; i < 500; ++i) ASSERT_EQ(step(model, ws, 1e-3, Drive{}), Status::Ok);
  step(model, ws, NAN, Drive{});
  EXPECT_EQ(g_allocations - before, 0);
}

}  // namespace
}  // namespace rdyn::reduced
