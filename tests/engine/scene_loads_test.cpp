// The scene's loads in the full model (engine/scene_loads.cpp) through inverse dynamics: on a
// lone crank without gravity m2 = 0 and the drive the motion needs is −F*(q̇), so each load law
// shows as a closed form — the motor's torque–speed line, a gate open only while its joint's
// rate has the gate's sign — and the motor's power integrates to the work column.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/forward_dynamics.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::engine {
namespace {

std::string crank_with(const std::string& loads) {
  return R"(name: crank
ground_points: {O: [0, 0]}
bodies:
  - {name: crank, mass_kg: 1.0, com_m: [0.05, 0], inertia_kgm2: 2.0e-3, points: {B: [0.1, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank}
independent: crank
loads:
)" + loads + R"(gravity: {enabled: false}
initial: {q_deg: 0, qdot: 1.0}
)";
}

TEST(SceneLoads, TheMotorLineAndTheGateAsClosedForms) {
  const FullModel motor(models::parse_scene(
      crank_with("  - {type: motor, name: m, joint: crank, stall_torque_Nm: 3.0, no_load_speed_rad_s: 12.0}\n"),
      "motor.yaml"));
  const FullModel gated(models::parse_scene(
      crank_with("  - {type: joint_torque, name: t, joint: crank, torque_Nm: 0.7, active_when: {joint: crank, rate: "
                 "negative}}\n"),
      "gated.yaml"));
  FullWorkspace wm(motor), wg(gated);
  for (const double w : {-5.0, 0.5, 4.0, 15.0}) {
    // T_act = m1 q̈ + m2 q̇² − F* with q̈ = 0, m2 = 0 (a lone crank): −F*.
    EXPECT_NEAR(calc_kinetostatic(motor, wm, 0.3, w, 0.0, Loads::All).driving_force, -3.0 * (1 - w / 12.0), 1e-12)
        << w;
    EXPECT_NEAR(calc_kinetostatic(gated, wg, 0.3, w, 0.0, Loads::All).driving_force, w < 0 ? -0.7 : 0.0, 1e-12)
        << w;
    // Loads::Conservative leaves both out.
    EXPECT_NEAR(calc_kinetostatic(motor, wm, 0.3, w, 0.0, Loads::Conservative).driving_force, 0.0, 1e-12);
  }
}

TEST(SceneLoads, TheMotorsWorkIsItsPowerIntegrated) {
  // Forward dynamics from 1 rad/s: m1 ω̇ = τs (1 − ω/ω0), so ω → ω0 exponentially and the work
  // of the motor W = ΔE (no other load): the energy column minus E0 equals the work column.
  const FullModel motor(models::parse_scene(
      crank_with("  - {type: motor, name: m, joint: crank, stall_torque_Nm: 0.05, no_load_speed_rad_s: 12.0}\n"),
      "motor.yaml"));
  ForwardOptions opt;
  opt.duration_s = 2.0;
  opt.output_interval_s = 0.1;
  const auto ts = simulate_full(motor, opt);
  const double m1 = 2.0e-3 + 1.0 * 0.05 * 0.05, tau = m1 * 12.0 / 0.05;  // time constant m1 ω0 / τs
  for (size_t i = 0; i < ts.t.size(); ++i) {
    EXPECT_NEAR(ts.qdot[i], 12.0 - 11.0 * std::exp(-ts.t[i] / tau), 1e-7) << ts.t[i];
    EXPECT_NEAR(ts.energy[i] - ts.energy[0], ts.work[i], 1e-9) << ts.t[i];
  }
  EXPECT_GT(ts.work.back(), 0.0);
}

}  // namespace
}  // namespace rdyn::engine
