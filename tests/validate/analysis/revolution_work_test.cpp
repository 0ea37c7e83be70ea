// The work per revolution (validate/analysis/revolution_work.cpp): a flywheel's closed form
// (r = w = 1: a torque does T·2π, a viscous brake −c·ω·2π, a motor s·(1 − ω/ω0)·2π), and on the
// bicycle (gated hip torques, a geared brake) and the slider-crank (a motor) the sums of one
// lookup per column and point, bit for bit (its one-locate evaluation must not change a digit).
#include "validate/analysis/revolution_work.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "models/scene_yaml.hpp"
#include "reduced/table.hpp"
#include "engine/full_model.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibration_load.hpp"

namespace rdyn::validate {
namespace {

// The scene's reduced model on a 10° fourier table, the selected loads at unit value.
reduced::ReducedModel unit_model(const models::Scene& scene, const Selection& sel) {
  const engine::FullModel full(scene);
  const auto e = extract_from_full(full, 10.0, reduced::Method::Kinetostatic);
  auto m = reduced::make_reduced_model(e.samples, scene, reduced::Interpolation::Fourier);
  set_load(m, sel, 1.0);
  return m;
}

TEST(RevolutionWork, FlywheelClosedForm) {
  const auto scene = models::parse_scene(
      "name: flywheel\n"
      "bodies: [{name: wheel, mass_kg: 2.0, inertia_kgm2: 0.05}]\n"
      "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]\n"
      "independent: wheel\n"
      "loads:\n"
      "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}\n"
      "  - {type: joint_torque, name: a, joint: wheel, torque_Nm: -0.3}\n"
      "  - {type: joint_torque, name: b, joint: wheel, torque_Nm: 0.1}\n"
      "  - {type: motor, name: m, joint: wheel, stall_torque_Nm: 0.5, no_load_speed_rad_s: 20.0}\n"
      "initial: {q_deg: 0, qdot: 5.0}\n",
      "f.yaml");
  CalibrationOptions opt;
  opt.load = "a";
  opt.load_field = "--load";
  const Selection sel = select_load(scene, opt);
  const auto m = unit_model(scene, sel);
  const double f = 0.8, w = 2 * M_PI * f, turn = 2 * M_PI;
  const RevolutionWork r = calc_revolution_work(m, sel, 0.3, f);
  EXPECT_NEAR(r.unit, -turn, 1e-12);  // a at unit value keeps its sign
  EXPECT_NEAR(r.brakes, -0.02 * w * turn, 1e-12);
  ASSERT_EQ(r.motor.size(), 1u);
  EXPECT_NEAR(r.motor[0], 0.5 * (1 - w / 20.0) * turn, 1e-12);
  EXPECT_NEAR(r.torque[1], 0.1 * turn, 1e-12);
  EXPECT_NEAR(r.other, r.brakes + r.motor[0] + r.torque[1], 1e-12);
  EXPECT_NEAR(r.scale, turn, 1e-12);
}

// The same sums with one Table::eval per column and point (what calc_revolution_work computed
// before its one locate per point).
RevolutionWork per_lookup(const reduced::ReducedModel& m, double q_start, double cadence_hz) {
  const int n = 3600;
  const double qd = 2 * M_PI * cadence_hz, dq = 2 * M_PI / n;
  RevolutionWork w;
  for (int i = 0; i < n; ++i) {
    const double q = q_start + (i + 0.5) * dq;
    for (const auto& t : m.torques) {
      const bool on = t.gate < 0 || m.gates[t.gate].sign * m.table.eval(m.gates[t.gate].c_r, q) * qd > 0;
      const double r_j = (t.c_tau >= 0 ? m.table.eval(t.c_tau, q) : 1.0) * m.table.eval(t.c_r, q);
      if (on) w.unit += t.value * r_j * dq;  // every torque selected
    }
    for (const auto& mo : m.motors) {
      const double r_j = m.table.eval(mo.c_r, q);
      w.other += models::motor_torque(mo.stall, mo.no_load_speed, r_j * qd) * r_j * dq;
    }
    for (const auto& b : m.brakes) {
      const double wr = m.table.eval(b.c_w, q);
      w.brakes += models::resistance_torque(b.law, b.coefficient, wr * qd) * wr * dq;
    }
  }
  return w;
}

void expect_as_per_lookup(const std::string& name) {
  const auto scene = models::load_scene(name);
  const Selection sel = select_load(scene, CalibrationOptions{});  // every joint torque
  const auto m = unit_model(scene, sel);
  ASSERT_FALSE(m.torques.empty()) << name;
  for (double q0 : {scene.initial.q, 1.0}) {
    const RevolutionWork r = calc_revolution_work(m, sel, q0, 1.1), ref = per_lookup(m, q0, 1.1);
    EXPECT_NE(r.unit, 0.0) << name;
    EXPECT_EQ(r.unit, ref.unit) << name;
    EXPECT_EQ(r.brakes, ref.brakes) << name;
    double motors = 0.0;
    for (double x : r.motor) motors += x;
    if (!m.motors.empty()) {
      EXPECT_NE(motors, 0.0) << name;
    }
    EXPECT_EQ(r.other - r.brakes, motors) << name;  // only brakes and motors besides the torques
  }
}

TEST(RevolutionWork, AsOneLookupPerColumnOnTheBicycleAndTheSliderCrank) {
  expect_as_per_lookup("bicycle");
  expect_as_per_lookup("slider-crank");
}

}  // namespace
}  // namespace rdyn::validate
