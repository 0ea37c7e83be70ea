#include "validate/analysis/revolution_work.hpp"

#include <algorithm>
#include <cmath>

#include "models/scene.hpp"

namespace rdyn::validate {

RevolutionWork calc_revolution_work(const reduced::ReducedModel& m, const Selection& sel, double q_start,
                                    double cadence_hz) {
  const int n = 3600;
  const double qd = 2 * M_PI * cadence_hz, dq = 2 * M_PI / n;
  std::vector<char> selected_torque(m.torques.size(), 0), selected_motor(m.motors.size(), 0),
      selected_force(m.point_forces.size(), 0);
  for (const auto& en : sel.entries)
    (en.motor ? selected_motor : en.point_force ? selected_force : selected_torque)[en.index] = 1;
  // Every column the loads read, located once per point (Table::eval_cols: Table::eval's
  // arithmetic, the same values bit for bit): 3600 points × 5 lookups were ~0.95 M instructions of
  // a ~30 M sweep case (issue #28).
  std::vector<int> cols, pos(static_cast<size_t>(m.table.cols), -1);
  auto use = [&](int c) {
    if (c >= 0 && pos[c] < 0) pos[c] = static_cast<int>(cols.size()), cols.push_back(c);
  };
  for (const auto& t : m.torques) use(t.gate >= 0 ? m.gates[t.gate].c_r : -1), use(t.c_tau), use(t.c_r);
  for (const auto& f : m.point_forces) use(f.gate >= 0 ? m.gates[f.gate].c_r : -1), use(f.c_tau), use(f.c_r);
  for (const auto& mo : m.motors) use(mo.c_r);
  for (const auto& b : m.brakes) use(b.c_w);
  std::vector<double> v(cols.size());
  auto at = [&](int c) { return v[pos[c]]; };
  RevolutionWork w;
  w.torque.assign(m.torques.size(), 0.0), w.force.assign(m.point_forces.size(), 0.0);
  w.motor.assign(m.motors.size(), 0.0);
  for (int i = 0; i < n; ++i) {
    const double q = q_start + (i + 0.5) * dq;
    m.table.eval_cols(q, cols.data(), static_cast<int>(cols.size()), v.data());
    for (size_t k = 0; k < m.torques.size(); ++k) {
      const auto& t = m.torques[k];
      const bool on = t.gate < 0 || m.gates[t.gate].sign * at(m.gates[t.gate].c_r) * qd > 0;
      // Generalized force per unit value: τ(θ(q))·r_j for a profiled load, r_j otherwise.
      const double tau = t.c_tau >= 0 ? at(t.c_tau) : 1.0;
      const double r_j = tau * at(t.c_r);
      if (selected_torque[k]) w.scale += std::abs(r_j) * dq;
      if (on) (selected_torque[k] ? w.unit : w.other) += t.value * r_j * dq;  // value ±1 when selected
      if (on && !selected_torque[k]) w.other_scale += std::abs(t.value * r_j) * dq, w.torque[k] += t.value * r_j * dq;
    }
    // Point forces: T·τ·(−dL/dq) per unit tension, gated like torques (Qpf column as the ratio).
    for (size_t k = 0; k < m.point_forces.size(); ++k) {
      const auto& f = m.point_forces[k];
      const bool on = f.gate < 0 || m.gates[f.gate].sign * at(m.gates[f.gate].c_r) * qd > 0;
      const double Q = (f.c_tau >= 0 ? at(f.c_tau) : 1.0) * at(f.c_r);
      if (selected_force[k]) w.scale += std::abs(Q) * dq;
      if (on) (selected_force[k] ? w.unit : w.other) += f.value * Q * dq;
      if (on && !selected_force[k]) w.other_scale += std::abs(f.value * Q) * dq, w.force[k] += f.value * Q * dq;
    }
    for (size_t k = 0; k < m.motors.size(); ++k) {
      const auto& mo = m.motors[k];
      const double r_j = at(mo.c_r);
      const double wm = models::motor_torque(mo.stall, mo.no_load_speed, r_j * qd) * r_j * dq;
      if (selected_motor[k]) {
        w.unit += wm;
        w.scale += std::abs(r_j) * dq;
        w.max_motor_rate = std::max(w.max_motor_rate, r_j * qd / mo.no_load_speed);
      } else {
        w.other += wm;
        w.other_scale += std::abs(wm);
        w.motor[k] += wm;
      }
    }
    for (const auto& b : m.brakes) {
      const double wr = at(b.c_w);
      const double wb = models::resistance_torque(b.law, b.coefficient, wr * qd) * wr * dq;
      w.other += wb;
      w.other_scale += std::abs(wb);
      w.brakes += wb;
    }
  }
  return w;
}

}  // namespace rdyn::validate
