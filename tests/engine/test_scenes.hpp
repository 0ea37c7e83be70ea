// Small scenes shared by the engine tests, written inline so that each test states
// the geometry its closed form uses.
#pragma once

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace rdyn::test {

// Parallelogram four-bar: crank A→B = rocker D→C = a, coupler B→C = ground A→D = d.
// On its parallelogram branch the coupler translates, so the reduced inertia is constant:
// m1 = (I_crank + m_crank·(a/2)²) + (I_rocker + m_rocker·(a/2)²) + m_coupler·a².
inline std::string parallelogram_yaml(double torque_Nm, bool gravity) {
  return std::string(R"(
name: parallelogram
ground_points: {A: [0, 0], D: [0.3, 0]}
bodies:
  - {name: crank, mass_kg: 0.5, com_m: [0.05, 0], inertia_kgm2: 4.0e-4, points: {B: [0.1, 0]}}
  - {name: coupler, mass_kg: 1.2, com_m: [0.15, 0], inertia_kgm2: 9.0e-3, points: {C: [0.3, 0]}}
  - {name: rocker, mass_kg: 0.7, com_m: [0.05, 0], inertia_kgm2: 6.0e-4, points: {C: [0.1, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank, guess_deg: 40}
  - {name: coupler, type: revolute, parent: crank, parent_point: B, child: coupler, guess_deg: -40}
  - {name: rocker, type: revolute, parent: ground, parent_point: D, child: rocker, guess_deg: 40}
loops:
  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}
independent: crank
loads:
  - {type: joint_torque, name: drive, joint: crank, torque_Nm: )") +
         std::to_string(torque_Nm) + R"(}
gravity: {enabled: )" + (gravity ? "true" : "false") + R"(}
outputs:
  constraint_forces:
    - {name: rocker_axial, joint: rocker, direction: C}
initial: {q_deg: 40, qdot: 1.0}
)";
}
inline double parallelogram_m1() {
  const double a = 0.1;
  return (4.0e-4 + 0.5 * 0.05 * 0.05) + (6.0e-4 + 0.7 * 0.05 * 0.05) + 1.2 * a * a;
}

// The shipped four-bar (models/scenes/fourbar.yaml) with `loads` added before its bearing,
// whose viscous coefficient becomes `bearing` [N·m·s].
inline std::string fourbar_with_loads(const std::string& loads, const std::string& bearing = "1.0e-3") {
  std::ifstream in(std::string(RDYN_SCENES) + "/fourbar.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const auto c = yaml.find("coefficient: 1.0e-3");
  if (c != std::string::npos) yaml.replace(c, 19, "coefficient: " + bearing);
  const auto at = yaml.find("loads:\n");
  return at == std::string::npos ? "" : yaml.insert(at + 7, loads);
}

// Drive loads for fourbar_with_loads: a crank torque profiled by the rocker's angle (a table,
// gated by the rocker's rate) beside a Fourier profile of the crank's own angle; and a point
// force from a ground point to the coupler, reading the rocker's angle, on while the rocker
// turns back. With the bearing at 0.05 N·m·s the torques drive the crank about 5 turns in 3 s.
inline constexpr const char* kFourbarProfiledTorques =
    "  - {type: joint_torque, name: push, joint: crank, torque_Nm: 0.5, active_when: {joint: rocker, rate: negative},\n"
    "     profile: {of: rocker, table_deg: [[0, 0.2], [60, 0.5], [85, 1.0], [100, 1.4], [120, 0.6], [240, 0.1]]}}\n"
    "  - {type: joint_torque, name: wave, joint: crank, profile: {of: crank, fourier: {a0: 1.5, a: [0.5], b: [0, "
    "0.3]}}}\n";
inline constexpr const char* kFourbarGatedPointForce =
    "  - {type: point_force, name: m, body_a: ground, point_a: [0.1, 0.35], body_b: coupler, point_b: [0.2, 0.03],\n"
    "     force_N: 6, active_when: {joint: rocker, rate: negative},\n"
    "     profile: {of: rocker, fourier: {a0: 1, a: [0.4], b: [0.2]}}}\n";

}  // namespace rdyn::test

namespace rdyn::test {

// A crank turning about the ground origin O, pulled by a point force of tension `tension_N`
// from ground point G = (0.25, 0.1) m to its point B = (0.1, 0) m (no gravity, no dissipation).
// Closed form: B(q) = 0.1 (cos q, sin q), L = |B − G|, dL/dq = (B − G)·B'(q)/L.
inline std::string pulled_crank_yaml(double tension_N, const std::string& extra = "") {
  return R"(
name: pulled_crank
ground_points: {O: [0, 0], G: [0.25, 0.1]}
bodies:
  - {name: crank, mass_kg: 1.0, com_m: [0.05, 0], inertia_kgm2: 2.0e-3, points: {B: [0.1, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank}
independent: crank
loads:
  - {type: point_force, name: m, body_a: ground, point_a: G, body_b: crank, point_b: B, force_N: )" +
         std::to_string(tension_N) + extra + R"(}
gravity: {enabled: false}
initial: {q_deg: 150, qdot: 2.0}
simulation: {duration_s: 2, output_interval_s: 0.01}
)";
}
inline double pulled_crank_length(double q) {
  return std::hypot(0.1 * std::cos(q) - 0.25, 0.1 * std::sin(q) - 0.1);
}
inline double pulled_crank_dL_dq(double q) {
  const double dx = 0.1 * std::cos(q) - 0.25, dy = 0.1 * std::sin(q) - 0.1;
  return (dx * -0.1 * std::sin(q) + dy * 0.1 * std::cos(q)) / std::hypot(dx, dy);
}

}  // namespace rdyn::test

namespace rdyn::test {

// The published branch-switching case (issue #22 item 2), one loop of it: a parallelogram of
// uniform 1 m, 1 kg rods (I = m L²/12 about the centre) on ground pivots A (0, 0) and D (1, 0),
// under gravity, both cranks vertical at the start and the crank turning at 1 rad/s. It falls
// through its aligned (flat, singular) positions at q = 0 and 180°, where the antiparallelogram
// branch crosses.
inline std::string rod_parallelogram_yaml(const std::string& simulation = "{duration_s: 6, output_interval_s: 0.01}") {
  return R"(
name: rod-parallelogram
ground_points: {A: [0, 0], D: [1, 0]}
bodies:
  - {name: crank, mass_kg: 1, com_m: [0.5, 0], inertia_kgm2: 0.0833333333333333, points: {B: [1, 0]}}
  - {name: coupler, mass_kg: 1, com_m: [0.5, 0], inertia_kgm2: 0.0833333333333333, points: {C: [1, 0]}}
  - {name: rocker, mass_kg: 1, com_m: [0.5, 0], inertia_kgm2: 0.0833333333333333, points: {C: [1, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank, guess_deg: 90}
  - {name: coupler, type: revolute, parent: crank, parent_point: B, child: coupler, guess_deg: -90}
  - {name: rocker, type: revolute, parent: ground, parent_point: D, child: rocker, guess_deg: 90}
loops:
  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}
independent: crank
gravity: {enabled: true}
initial: {q_deg: 90, qdot: 1.0}
simulation: )" + simulation + "\n";
}

// The exact motion of models/scenes/chains/chain-N.yaml: all cranks turn alike and the couplers
// translate, so θ̈ = −(K/m1) cos θ with m1 = (N+1)/3 + N [kg·m²] and K = g[(N+1)/2 + N] [N·m]
// (cranks' centres at ½ sin θ, couplers' at sin θ). Classical RK4 at 1e-4 s: its global error,
// ~(1e-4)⁴ × 10 s × |θ⁽⁵⁾|, is below 1e-12 rad, far under the 1e-5 checked.
inline std::vector<double> chain_exact_q(int n_loops, double q0, double qdot0, double dt_out, int rows) {
  const double m1 = (n_loops + 1) / 3.0 + n_loops, K = 9.81 * ((n_loops + 1) / 2.0 + n_loops);
  auto acc = [&](double th) { return -K / m1 * std::cos(th); };
  const int sub = static_cast<int>(std::lround(dt_out / 1e-4));
  const double h = dt_out / sub;
  std::vector<double> q{q0};
  double th = q0, w = qdot0;
  for (int r = 1; r < rows; ++r) {
    for (int k = 0; k < sub; ++k) {
      const double k1q = w, k1w = acc(th);
      const double k2q = w + 0.5 * h * k1w, k2w = acc(th + 0.5 * h * k1q);
      const double k3q = w + 0.5 * h * k2w, k3w = acc(th + 0.5 * h * k2q);
      const double k4q = w + h * k3w, k4w = acc(th + h * k3q);
      th += h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q);
      w += h / 6 * (k1w + 2 * k2w + 2 * k3w + k4w);
    }
    q.push_back(th);
  }
  return q;
}

}  // namespace rdyn::test
