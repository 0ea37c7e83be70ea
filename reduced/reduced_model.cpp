#include "reduced/reduced_model.hpp"

#include <algorithm>
#include <utility>
#include <cmath>

#include <fmt/format.h>

#include "models/scene_hash.hpp"
#include "reduced/samples_fit.hpp"

namespace rdyn::reduced {

namespace {

// Where the interpolant through samples with a wrong value at a pole is still off, in grid
// steps: linear and Akima are local (the sample's own intervals; Akima's slopes reach two more);
// a cubic spline is global but its response to one sample decays by 2 + √3 per step, 8 steps
// ≈ 3.7⁻⁸ ≈ 3e-5; a trigonometric interpolant's decays only like 1/distance: the whole turn.
double pole_band(const Samples& s, const std::string& fit) {
  if (fit == interpolation_name(Interpolation::Fourier)) return INFINITY;
  if (fit == interpolation_name(Interpolation::Linear)) return 1.0 * s.step;
  if (fit == interpolation_name(Interpolation::Akima)) return 3.0 * s.step;
  return 8.0 * s.step;
}

void set_force_poles(const Samples& s, ReducedModel& m) {
  m.force_poles.assign(m.force_names.size(), {});
  for (const auto& [force, qs] : s.poles) {
    const auto it = std::find(m.force_names.begin(), m.force_names.end(), force);
    if (it == m.force_names.end())
      throw TableError(fmt::format("{} lists a pole of constraint force '{}', which the scene does not declare",
                                   s.file.empty() ? "the table" : "table " + s.file, force.substr(0, 40)));
    m.force_poles[it - m.force_names.begin()] = qs;
  }
  m.pole_band = pole_band(s, m.table.fit);
}

// The one place that says which columns a reduced model reads, each index from col(name): the column
// fields, the gates (column and sign; roots need the samples), rhs_cols and out_cols.
template <typename Col>
ReducedModel resolve_columns(const models::Scene& scene, Col&& col) {
  ReducedModel m;
  m.c_m1 = col("m1");
  m.c_m2 = col("m2");
  m.c_V = col("V");
  m.c_Q = col("Q_cons");
  for (const auto& f : scene.outputs.constraint_forces) {
    m.force_names.push_back(f.name);
    m.c_me1.push_back(col("me1_" + f.name));
    m.c_me2.push_back(col("me2_" + f.name));
    m.c_Qx.push_back(col("Qx_cons_" + f.name));
  }
  auto rx_cols = [&](const std::string& prefix, const std::string& what) {
    std::vector<int> c;
    for (const auto& f : scene.outputs.constraint_forces) c.push_back(col(prefix + f.name + "_" + what));
    return c;
  };
  m.rhs_cols = {m.c_m1, m.c_m2, m.c_Q};
  // The gate of a load: its index in m.gates, −1 when the load always acts.
  auto add_gate = [&](const std::optional<models::RateGate>& active_when) {
    if (!active_when) return -1;
    m.gates.push_back(ReducedModel::Gate{col("r_" + active_when->joint), active_when->sign, {}, 1.0, {}});
    return static_cast<int>(m.gates.size()) - 1;
  };
  for (const auto& t : scene.joint_torques) {
    ReducedModel::Torque tq{t.value, col("r_" + t.joint), rx_cols("rx_", t.joint), -1};
    tq.gate = add_gate(t.active_when);
    if (t.profile) tq.c_tau = col("tau_" + t.name);
    m.torques.push_back(tq);
    m.rhs_cols.push_back(tq.c_r);
    if (tq.c_tau >= 0) m.rhs_cols.push_back(tq.c_tau);
  }
  for (const auto& mo : scene.motors) {
    m.motors.push_back({mo.stall_torque, mo.no_load_speed, col("r_" + mo.joint), rx_cols("rx_", mo.joint)});
    m.rhs_cols.push_back(m.motors.back().c_r);
  }
  for (const auto& r : scene.resistances) {
    m.brakes.push_back({r.law, r.coefficient, col("w_" + r.body), rx_cols("wx_", r.body)});
    m.rhs_cols.push_back(m.brakes.back().c_w);
  }
  for (const auto& f : scene.point_forces) {
    std::vector<int> cx;
    for (const auto& c : scene.outputs.constraint_forces) cx.push_back(col("Qxpf_" + c.name + "_" + f.name));
    ReducedModel::Torque pf{f.value, col("Qpf_" + f.name), cx, add_gate(f.active_when)};
    if (f.profile) pf.c_tau = col("tau_" + f.name);
    m.point_forces.push_back(pf);
    m.rhs_cols.push_back(pf.c_r);
    if (pf.c_tau >= 0) m.rhs_cols.push_back(pf.c_tau);
  }
  // Last, V: the divergence guard's energy from q̈'s own lookup (calc_acceleration_energy).
  m.rhs_cols.push_back(m.c_V);
  m.out_cols = {m.c_m1, m.c_V};
  for (size_t k = 0; k < m.c_me1.size(); ++k) {
    m.out_cols.insert(m.out_cols.end(), {m.c_me1[k], m.c_me2[k], m.c_Qx[k]});
    for (const auto& t : m.torques) {
      m.out_cols.push_back(t.c_rx[k]);
      if (t.c_tau >= 0) m.out_cols.push_back(t.c_tau);
    }
    for (const auto& mo : m.motors) m.out_cols.insert(m.out_cols.end(), {mo.c_r, mo.c_rx[k]});
    for (const auto& b : m.brakes) m.out_cols.insert(m.out_cols.end(), {b.c_w, b.c_wx[k]});
    for (const auto& f : m.point_forces) {
      m.out_cols.push_back(f.c_rx[k]);
      if (f.c_tau >= 0) m.out_cols.push_back(f.c_tau);
    }
  }
  return m;
}

// A gate with its ratio's exact zeros: the product of sines, oriented like r farthest from any root.
void set_gate_orientation(const Samples& s, const Table& table, ReducedModel::Gate& g) {
  const auto* roots = s.roots_of(s.names[g.c_r]);
  if (!roots || !s.periodic || roots->empty() || roots->size() % 2 != 0) return;
  set_gate_roots(g, *roots);
  double best = -1, q_best = s.q[0];
  for (double q : s.q) {
    double d = INFINITY;
    for (double r : g.roots) d = std::min(d, std::abs(std::remainder(q - r, 2 * M_PI)));
    if (d > best) best = d, q_best = q;
  }
  const double r_val = table.eval(g.c_r, q_best);
  double prod = 1.0;
  for (double r : g.roots) prod *= std::sin(0.5 * (q_best - r));
  g.root_sign = (r_val > 0) == (prod > 0) ? 1.0 : -1.0;
}

}  // namespace

std::vector<std::string> reduced_model_columns(const models::Scene& scene) {
  std::vector<std::string> names;  // each name once, in the order first required
  auto col = [&](const std::string& name) {
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    return static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
  };
  resolve_columns(scene, col);
  return names;
}

ReducedModel make_reduced_model(const Samples& s, const models::Scene& scene, Table table) {
  check_samples_fit(s, scene);
  ReducedModel m = resolve_columns(scene, [&](const std::string& name) { return s.require(name); });
  m.table = std::move(table);
  m.min_edge = s.min_edge;
  m.max_edge = s.max_edge;
  m.revolute = s.revolute;
  set_force_poles(s, m);
  for (auto& g : m.gates) set_gate_orientation(s, m.table, g);
  // The interpolated reduced inertia must stay positive (Eksergian divides by it); a coarse
  // grid over a sharp inertia peak can undershoot. Each interval's cubic read from its
  // coefficients (Table::eval's formula without locating q: 1440 × 16 evaluations of a fourier
  // table were 3 % of a sweep case).
  for (int iv = 0; iv < m.table.intervals; ++iv)
    for (int k = 0; k < 16; ++k) {
      const double* c = &m.table.coef[(static_cast<size_t>(iv) * m.table.cols + m.c_m1) * 4];
      const double dx = k / 16.0 * m.table.step, q = m.table.q0 + (iv + k / 16.0) * m.table.step;
      const double m1 = (c[0] + dx * c[1]) + dx * dx * (c[2] + dx * c[3]);
      if (!(m1 > 0))
        throw TableError(fmt::format("the interpolated reduced inertia m1 = {:.3g} is not positive at {} "
                                     "(outside the validity domain): use a finer grid or another interpolation",
                                     m1, describe_q(m.revolute, q, 4)));
    }
  m.record_cols = m.rhs_cols;
  m.record_cols.insert(m.record_cols.end(), m.out_cols.begin(), m.out_cols.end());
  m.rhs_block = make_column_block(m.table, m.rhs_cols);
  m.record_block = make_column_block(m.table, m.record_cols);
  return m;
}

ReducedModel make_reduced_model(const Samples& s, const models::Scene& scene, Interpolation interp,
                                bool energy_consistent_m2) {
  check_samples_fit(s, scene);  // before the table is built
  return make_reduced_model(s, scene, build_table(s, interp, energy_consistent_m2));
}

ReducedWorkspace::ReducedWorkspace(const ReducedModel& m)
    : gate_on(m.gates.size(), 1),
      torque_value(m.torques.size()),
      scratch(m.rhs_cols.size()),
      scratch_out(m.out_cols.size()),
      scratch_rec(m.record_cols.size()),
      switching(m.gates.size()) {
  for (size_t i = 0; i < m.torques.size(); ++i) torque_value[i] = m.torques[i].value;
}

namespace {

// Eksergian's right-hand side from the rhs_cols values v.
void acceleration_from(const ReducedModel& m, const ReducedWorkspace& ws, const double* v, double qdot,
                       double& qddot, double& power_nc) {
  const double m1 = v[0], m2 = v[1];
  // 1/m1 first: the division then runs beside the load sums instead of after them (RK4's
  // stages form one chain, so its latency is the step's; issue #11 item 6).
  const double inv_m1 = 1.0 / m1;
  double F_nc = 0.0;  // generalized force of the non-conservative loads on q
  const double* r = v + 3;
  for (size_t i = 0; i < m.torques.size(); ++i) {
    const auto& t = m.torques[i];
    // Profiled: value·τ(θ_of(q))·r_j, the profile tabulated next to r.
    const double tau = t.c_tau >= 0 ? r[1] : 1.0;
    if (t.gate < 0 || ws.gate_on[t.gate]) F_nc += ws.torque_value[i] * tau * *r;
    r += t.c_tau >= 0 ? 2 : 1;
  }
  for (const auto& mo : m.motors) {
    const double u = *r * qdot;  // joint rate
    F_nc += models::motor_torque(mo.stall, mo.no_load_speed, u) * *r;
    ++r;
  }
  for (const auto& b : m.brakes) {
    F_nc += models::resistance_torque(b.law, b.coefficient, *r * qdot) * *r;
    ++r;
  }
  for (const auto& f : m.point_forces) {  // T·[τ]·(−dL/dq), the Qpf column next to its tau
    const double tau = f.c_tau >= 0 ? r[1] : 1.0;
    if (f.gate < 0 || ws.gate_on[f.gate]) F_nc += f.value * tau * *r;
    r += f.c_tau >= 0 ? 2 : 1;
  }
  // Eksergian: m1 q̈ + m2 q̇² = Q_cons + F_nc
  qddot = (v[2] + F_nc - m2 * qdot * qdot) * inv_m1;
  power_nc = F_nc * qdot;
}

// Energy and constraint forces from the out_cols values v.
double outputs_from(const ReducedModel& m, const ReducedWorkspace& ws, const double* v, double qdot, double qddot,
                    double* forces);

}  // namespace

void calc_acceleration(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double& qddot,
                       double& power_nc) {
  double* v = ws.scratch.data();
  eval_block(m.table, m.rhs_block, q, v);
  acceleration_from(m, ws, v, qdot, qddot, power_nc);
}

double calc_acceleration_energy(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double& qddot,
                                double& power_nc) {
  double* v = ws.scratch.data();
  eval_block(m.table, m.rhs_block, q, v);
  acceleration_from(m, ws, v, qdot, qddot, power_nc);
  return 0.5 * v[0] * qdot * qdot + v[m.rhs_cols.size() - 1];  // ½ m1 q̇² + V, V the last rhs column
}

double calc_switching(const ReducedModel& m, int g, double q, double qdot) {
  const auto& gate = m.gates[g];
  if (gate.roots.empty()) return gate.sign * m.table.eval(gate.c_r, q) * qdot;
  double prod = gate.root_sign;
  if (2 * gate.pairs.size() == gate.roots.size()) {
    // cos(q − mid) is 2π-periodic itself: no wrap (its rounding, ~|q|·eps, is the wrap's own).
    for (const auto& p : gate.pairs) prod *= 0.5 * (p.cos_half_gap - std::cos(q - p.mid));
    return gate.sign * prod * qdot;
  }
  // Wrap q into the table's period first (even root count: the product is 2π-periodic), so
  // long runs keep small sine arguments.
  const double P = m.table.period;
  const double qw = q - P * std::floor((q - m.table.q0) / P);
  for (double r : gate.roots) prod *= std::sin(0.5 * (qw - r));
  return gate.sign * prod * qdot;
}

const double* calc_switching_all(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot) {
  if (q != ws.switching_q || qdot != ws.switching_qdot) {
    for (size_t g = 0; g < m.gates.size(); ++g) ws.switching[g] = calc_switching(m, static_cast<int>(g), q, qdot);
    ws.switching_q = q, ws.switching_qdot = qdot;
  }
  return ws.switching.data();
}

void set_gate_roots(ReducedModel::Gate& gate, std::vector<double> roots) {
  gate.roots = std::move(roots);
  gate.pairs.clear();
  if (gate.roots.size() % 2 != 0) return;
  // Neighbouring roots pair up; a pair closer than 1e-3 rad keeps the product of sines (the
  // difference of cosines would lose about −log10(gap²) digits near its roots).
  std::vector<ReducedModel::Gate::RootPair> pairs;
  for (size_t k = 0; k + 1 < gate.roots.size(); k += 2) {
    const double a = gate.roots[k], b = gate.roots[k + 1];
    if (!(std::abs(std::sin(0.5 * (a - b))) > 1e-3)) return;
    const double c = std::cos(0.5 * (a - b));
    pairs.push_back({c, 0.5 * (a + b), std::acos(std::clamp(c, -1.0, 1.0))});
  }
  gate.pairs = std::move(pairs);
}

void init_gates(const ReducedModel& m, ReducedWorkspace& ws) {
  for (size_t g = 0; g < m.gates.size(); ++g) {
    const double s = calc_switching(m, static_cast<int>(g), ws.q, ws.qdot);
    if (std::abs(s) > 1e-12) {
      ws.gate_on[g] = s > 0;
      continue;
    }
    // From rest: on if, switched on, it drives its joint the gated way (r·q̈ has its sign).
    ws.gate_on[g] = 1;
    double qdd, p;
    calc_acceleration(m, ws, ws.q, ws.qdot, qdd, p);
    ws.gate_on[g] = calc_switching(m, static_cast<int>(g), ws.q, qdd) > 0;
  }
}

double calc_energy(const ReducedModel& m, double q, double qdot) {
  // Both columns from one interval search (Table::eval_cols: the same values as two evals).
  const int cols[2] = {m.c_m1, m.c_V};
  double v[2];
  m.table.eval_cols(q, cols, 2, v);
  return 0.5 * v[0] * qdot * qdot + v[1];
}

double calc_drive(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double qddot, double& power_nc,
                  double* forces) {
  ws.q = q, ws.qdot = qdot;
  for (size_t g = 0; g < m.gates.size(); ++g) {
    const double s = calc_switching(m, static_cast<int>(g), q, qdot);
    ws.gate_on[g] = std::abs(s) > 1e-12 ? s > 0 : calc_switching(m, static_cast<int>(g), q, qddot) > 0;
  }
  double* v = ws.scratch_rec.data();
  eval_block(m.table, m.record_block, q, v);
  double qddot_free = 0.0;
  acceleration_from(m, ws, v, qdot, qddot_free, power_nc);
  outputs_from(m, ws, v + m.rhs_cols.size(), qdot, qddot, forces);
  return v[0] * (qddot - qddot_free);  // m1 (q̈ − q̈_free)
}

double calc_potential_min(const ReducedModel& m) {
  const Table& t = m.table;
  const int nodes = t.periodic ? t.intervals : t.intervals + 1;
  double v_min = t.eval(m.c_V, t.q0);
  for (int i = 1; i < nodes; ++i) v_min = std::min(v_min, t.eval(m.c_V, t.q0 + i * t.step));
  return v_min;
}

DivergenceGuard start_divergence_guard(double energy0, double potential_min, double work0) {
  DivergenceGuard g;
  g.energy0 = energy0;
  g.scale0 = std::max(0.0, energy0 - potential_min);
  g.work_max = std::abs(work0);
  return g;
}

double calc_sample(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double& qddot,
                   double& power_nc, double* forces) {
  double* v = ws.scratch_rec.data();
  eval_block(m.table, m.record_block, q, v);
  acceleration_from(m, ws, v, qdot, qddot, power_nc);
  return outputs_from(m, ws, v + m.rhs_cols.size(), qdot, qddot, forces);
}

namespace {
double outputs_from(const ReducedModel& m, const ReducedWorkspace& ws, const double* v, double qdot, double qddot,
                    double* forces) {
  const double energy = 0.5 * v[0] * qdot * qdot + v[1];  // ½ m1 q̇² + V
  const double* c = v + 2;
  for (size_t k = 0; k < m.c_me1.size(); ++k) {
    const double me1 = c[0], me2 = c[1];
    double Qx = c[2];  // Q_x,k: loads along x_k by virtual power (q̇ = 0, ẋ_k = 1)
    c += 3;
    for (size_t i = 0; i < m.torques.size(); ++i) {
      const auto& t = m.torques[i];
      const double tau = t.c_tau >= 0 ? c[1] : 1.0;
      if (t.gate < 0 || ws.gate_on[t.gate]) Qx += ws.torque_value[i] * tau * *c;
      c += t.c_tau >= 0 ? 2 : 1;
    }
    for (const auto& mo : m.motors) {
      Qx += models::motor_torque(mo.stall, mo.no_load_speed, c[0] * qdot) * c[1];
      c += 2;
    }
    for (const auto& b : m.brakes) {
      Qx += models::resistance_torque(b.law, b.coefficient, c[0] * qdot) * c[1];
      c += 2;
    }
    for (const auto& f : m.point_forces) {
      const double tau = f.c_tau >= 0 ? c[1] : 1.0;
      if (f.gate < 0 || ws.gate_on[f.gate]) Qx += f.value * tau * *c;
      c += f.c_tau >= 0 ? 2 : 1;
    }
    forces[k] = me1 * qddot + me2 * qdot * qdot - Qx;  // me1 q̈ + me2 q̇² = F_E + Q_x
  }
  return energy;
}
}  // namespace

namespace {

// Classical RK4 on y = (q, q̇, W) with frozen gates. k1: (q̈, power) at the step's start with
// these gates when the caller already has them (else null).
void rk4(const ReducedModel& m, ReducedWorkspace& ws, double h, const double* k1 = nullptr) {
  const double q = ws.q, v = ws.qdot;
  double a1, p1, a2, p2, a3, p3, a4, p4;
  if (k1)
    a1 = k1[0], p1 = k1[1];
  else
    calc_acceleration(m, ws, q, v, a1, p1);
  calc_acceleration(m, ws, q + 0.5 * h * v, v + 0.5 * h * a1, a2, p2);
  calc_acceleration(m, ws, q + 0.5 * h * (v + 0.5 * h * a1), v + 0.5 * h * a2, a3, p3);
  calc_acceleration(m, ws, q + h * (v + 0.5 * h * a2), v + h * a3, a4, p4);
  ws.q = q + h * (v + h / 6.0 * (a1 + a2 + a3));
  ws.qdot = v + h / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
  ws.work += h / 6.0 * (p1 + 2 * p2 + 2 * p3 + p4);
  ws.t += h;
}

constexpr double kTwoPi = 2 * 3.14159265358979323846;

// Whether gate g's switching is known in closed form: its switch angles in pairs.
bool predictable(const ReducedModel::Gate& gate) {
  return !gate.pairs.empty() && 2 * gate.pairs.size() == gate.roots.size();
}

// x − 2πk with k the nearest integer to x/2π (|result| ≤ π up to rounding), without libm: the
// truncating cast and one correction, as Table::locate (std::round is a library call here).
double wrap_to_pi(double x) {
  const double r = x * (1.0 / kTwoPi);
  if (!(std::abs(r) < 4.0e18)) return x - x;  // NaN (or beyond exact integers): no sign, no undefined cast
  const double k = static_cast<double>(static_cast<long>(r + (r >= 0 ? 0.5 : -0.5)));
  return x - k * kTwoPi;
}

// Sign (+1, −1, or 0 on a switch angle) of a predictable gate's switching function at (q, q̇)
// without a cosine: each pair's factor ½[cos((ρa−ρb)/2) − cos(q − mid)] is positive exactly
// where |wrap(q − mid)| exceeds half the gap (cos decreases on [0, π]). The same sign as
// calc_switching except within rounding of a switch angle.
int switching_sign(const ReducedModel::Gate& gate, double q, double qdot) {
  double sgn = gate.sign * gate.root_sign * (qdot > 0 ? 1.0 : qdot < 0 ? -1.0 : 0.0);
  for (const auto& p : gate.pairs) {
    const double x = std::abs(wrap_to_pi(q - p.mid));
    sgn *= x > p.half_gap ? 1.0 : x < p.half_gap ? -1.0 : 0.0;
  }
  return sgn > 0 ? 1 : sgn < 0 ? -1 : 0;
}

// Distance from q to the next image ρ + 2πk of a switch angle in the direction dir (±1), in
// [0, 2π), by the truncating cast and one correction (no libm floor on the hot path); NaN for a
// root far outside the turn (a hand-made table), which has no angle to reach.
double distance_ahead(double rho, double q, double dir) {
  const double x = dir * (rho - q) * (1.0 / kTwoPi);
  if (!(std::abs(x) < 1e15)) return NAN;
  double fl = static_cast<double>(static_cast<long>(x));
  if (fl > x) fl -= 1.0;
  return (x - fl) * kTwoPi;
}

// The first switch of the predictable gates along the Taylor path q(τ) = q0 + v0 τ + ½ a0 τ²,
// τ ∈ (0, h]: for each gate, the first switch angle (any image ρ + 2πk) the path reaches where
// the gate, as it stands, disagrees with the switching function's sign just beyond that angle
// (a gate already set for the far side, e.g. just switched a rounding short of its angle, is
// not switched again). Fills after[g] with that sign (1 on, 0 off) for the gates switching at
// the returned τ (±1e-9 relative; others −1), and returns τ, or +∞ when no switch is predicted.
// Only where q̇ keeps its sign over the step and the path spans less than a turn; elsewhere +∞
// and the switches are left to the check at the step's end. angle: the switch angle's image R
// the returned τ reaches; reach: |q(h) − q0| along the path.
double predict_switch(const ReducedModel& m, ReducedWorkspace& ws, double q0, double v0, double a0, double h,
                      size_t ng, int* after, double& angle, double& reach_out) {
  for (size_t g = 0; g < ng; ++g) after[g] = -1;
  const double v1 = v0 + a0 * h;
  if (!(v0 * v1 > 0) || !(std::abs(q0) < 1e15)) return INFINITY;  // also NaN; a huge q has no angle left
  const double dir = v0 > 0 ? 1.0 : -1.0;
  const double reach = dir * h * (v0 + 0.5 * a0 * h);  // |q(h) − q0|, monotone path
  if (!(reach < kTwoPi)) return INFINITY;
  reach_out = reach;
  double tau_min = INFINITY, R_min = 0.0;
  double tau_g[32];
  for (size_t g = 0; g < ng; ++g) {
    tau_g[g] = INFINITY;
    const auto& gate = m.gates[g];
    if (!predictable(gate)) continue;
    for (double rho : gate.roots) {
      const double dist = distance_ahead(rho, q0, dir);
      if (!(dist > 0 && dist <= reach)) continue;  // not reached in this step (the usual case), or no angle
      const double R = q0 + dir * dist;
      // Sign just beyond R in the direction of motion (a rounding-size step past the angle).
      const int sgn = switching_sign(gate, R + dir * 1e-9 * (1.0 + std::abs(R)), v0);
      if (sgn == 0 || (sgn > 0) == static_cast<bool>(ws.gate_on[g])) continue;  // nothing to switch
      // ½ a0 τ² + v0 τ − (R − q0) = 0, the root on the monotone branch (stable form).
      const double d = R - q0, disc = v0 * v0 + 2 * a0 * d;
      if (!(disc >= 0)) continue;
      const double tau = 2 * d / (v0 + dir * std::sqrt(disc));
      if (tau > 0 && tau <= h && tau < tau_g[g]) tau_g[g] = tau, after[g] = sgn > 0;
      if (tau > 0 && tau <= h && tau < tau_min) tau_min = tau, R_min = R;
    }
  }
  if (!std::isfinite(tau_min)) return INFINITY;
  // The quadratic path is off by O(τ³) (a few 1e-5 s at 20 ms steps on a lever whose inertia
  // varies fast, no better than the linear estimate after the step). One right-hand side at
  // its predicted crossing gives the jerk j = (q̈ − a0)/τ, and Newton on the cubic
  // q0 + v0 τ + ½ a0 τ² + ⅙ j τ³ = R the crossing to O(τ⁴): one evaluation per switch.
  double a_mid, p_mid;
  calc_acceleration(m, ws, q0 + tau_min * (v0 + 0.5 * a0 * tau_min), v0 + a0 * tau_min, a_mid, p_mid);
  const double j = (a_mid - a0) / tau_min;
  double tau = tau_min;
  for (int it = 0; it < 4 && std::isfinite(j); ++it) {
    const double f = q0 - R_min + tau * (v0 + tau * (0.5 * a0 + tau * j / 6.0));
    const double df = v0 + tau * (a0 + 0.5 * j * tau);
    if (!(df * dir > 0)) break;  // the cubic turns back: keep the last estimate
    tau -= f / df;
  }
  if (!(tau > 0 && tau <= h)) tau = tau_min;  // a correction leaving the step: the quadratic's
  angle = R_min;
  for (size_t g = 0; g < ng; ++g)
    if (!(tau_g[g] <= tau_min * (1 + 1e-9))) after[g] = -1;
  return tau;
}

// The gates as a bit mask (at most 32 gates are tracked).
unsigned gate_mask(const ReducedWorkspace& ws, size_t ng) {
  unsigned mask = 0;
  for (size_t g = 0; g < ng; ++g)
    if (ws.gate_on[g]) mask |= 1u << g;
  return mask;
}

// Records, at the workspace's state, where the next switch angle of any gate lies ahead in the
// direction of q̇ (the gates agree with their switching functions here: the caller has just
// checked). No record at rest, at a huge q, or on an angle itself.
void mark_ahead(const ReducedModel& m, ReducedWorkspace& ws, size_t ng) {
  ws.ahead_q = NAN;
  const double q = ws.q, v = ws.qdot;
  if (!(v != 0) || !(std::abs(q) < 1e15)) return;
  const double dir = v > 0 ? 1.0 : -1.0;
  double nearest = INFINITY;
  for (size_t g = 0; g < ng; ++g)
    for (double rho : m.gates[g].roots) {
      const double dist = distance_ahead(rho, q, dir);
      if (!std::isnan(dist)) nearest = std::min(nearest, dist);
    }
  if (!(nearest > 1e-12 * (1.0 + std::abs(q)) && std::isfinite(nearest))) return;
  ws.ahead_q = q, ws.ahead_qdot = v, ws.ahead_limit = q + dir * nearest;
  ws.ahead_gates = gate_mask(ws, ng);
}

}  // namespace

double step_fixed_rk4(const ReducedModel& m, ReducedWorkspace& ws, double h) { return step_fixed_rk4(m, ws, h, nullptr); }

namespace {

// The fast path of step_fixed_rk4: no switch angle ahead within this step's reach (the record
// mark_ahead left at this very state and gates): the step alone, without the prediction or the
// check at its end, which would find nothing (the same arithmetic, the same result). Issue #11
// item 6: the bicycle's RK4 steps cross an angle about one step in five. Returns true when the
// step is done; otherwise the state is unchanged and k1 points to the start derivative (computed
// into k1_storage when it was not given).
bool step_clear_of_switches(const ReducedModel& m, ReducedWorkspace& ws, double h, const double*& k1,
                            double k1_storage[2]) {
  const double q0 = ws.q, v0 = ws.qdot, t0 = ws.t, w0 = ws.work;
  if (!k1) {
    calc_acceleration(m, ws, q0, v0, k1_storage[0], k1_storage[1]);
    k1 = k1_storage;
  }
  const double dir = v0 > 0 ? 1.0 : -1.0, a0 = k1[0];
  const double reach = dir * h * (v0 + 0.5 * a0 * h);  // predict_switch's
  if (!(v0 * (v0 + a0 * h) > 0 && reach < dir * (ws.ahead_limit - q0))) return false;
  rk4(m, ws, h, k1);
  if (ws.qdot * v0 > 0 && dir * (ws.ahead_limit - ws.q) > 0) {
    ws.ahead_q = ws.q, ws.ahead_qdot = ws.qdot;  // the same angle is still ahead
    return true;
  }
  ws.q = q0, ws.qdot = v0, ws.t = t0, ws.work = w0;  // it passed the angle after all: the full step
  return false;
}

// Every gate agrees with its switching function's sign at the state: predictable gates are
// checked by sign (no cosine); false as soon as one disagrees or one is not predictable (its
// value is needed).
bool gates_agree_by_sign(const ReducedModel& m, const ReducedWorkspace& ws, size_t ng) {
  for (size_t g = 0; g < ng; ++g) {
    const auto& gate = m.gates[g];
    if (!predictable(gate)) return false;
    const int s1 = switching_sign(gate, ws.q, ws.qdot);
    if (s1 != 0 && static_cast<bool>(ws.gate_on[g]) != (s1 > 0)) return false;
  }
  return true;
}

// The check at a step's end from (q0, v0) to the workspace's state: the fraction of the step
// where the first disagreeing gate's switching function crossed zero (linear interpolation
// between the ends), fr[g] each gate's own (2 when it agrees at the end); > 1 when every gate
// agrees.
double first_switch_fraction(const ReducedModel& m, ReducedWorkspace& ws, double q0, double v0, size_t ng,
                             double fr[32]) {
  double s0[32];
  const double q1 = ws.q, v1 = ws.qdot;
  const double* sw = calc_switching_all(m, ws, q0, v0);
  for (size_t g = 0; g < ng; ++g) s0[g] = sw[g];
  double frac = 2.0;
  const double* sw1 = calc_switching_all(m, ws, q1, v1);
  for (size_t g = 0; g < ng; ++g) {
    const double s1 = sw1[g];
    fr[g] = 2.0;
    if (s1 == 0.0 || static_cast<bool>(ws.gate_on[g]) == (s1 > 0)) continue;  // agrees at the end
    fr[g] = ((s0[g] > 0) != (s1 > 0) && s0[g] != s1) ? s0[g] / (s0[g] - s1) : 0.0;
    frac = std::min(frac, fr[g]);
  }
  return frac;
}

}  // namespace

double step_fixed_rk4(const ReducedModel& m, ReducedWorkspace& ws, double h, const double* k1) {
  // Switches are handled one after another inside the step: a gate needs a flip in the
  // remaining interval exactly when it disagrees with the sign of its switching function at
  // the interval's end (as the full model's gates agree with their witnesses after events).
  // Each switch instant is estimated by linear interpolation of the switching function and
  // the step is split there. Allocation-free: at most 32 gates are tracked.
  const size_t ng = std::min<size_t>(m.gates.size(), 32);
  // Prediction only when every gate has its angles: a cut at a predicted switch would otherwise
  // pass over a switch of another gate before it, found only after the cut (and applied there,
  // late). A mixed model takes the check at the step's end for all its gates.
  bool all_predictable = ng > 0;
  for (size_t g = 0; g < ng; ++g) all_predictable &= predictable(m.gates[g]);
  double t_first = NAN;
  double remaining = h;
  double k1_ahead[2];  // outlives the block: k1 may point to it after
  if (all_predictable && ws.q == ws.ahead_q && ws.qdot == ws.ahead_qdot && gate_mask(ws, ng) == ws.ahead_gates &&
      step_clear_of_switches(m, ws, h, k1, k1_ahead))
    return t_first;
  bool agreed_at_end = false;
  for (int pass = 0; pass < 8 && remaining > 0; ++pass) {
    const double q0 = ws.q, v0 = ws.qdot, t0 = ws.t, w0 = ws.work;
    // The given start derivative holds until a gate flips (pass 0 and its shortened step).
    const double* k1_now = pass == 0 ? k1 : nullptr;
    double k1_own[2];
    if (all_predictable) {
      // Predict a switch of the gates with known switch angles from the start derivative (which
      // the step needs anyway) and cut the step there: one partial step instead of the whole
      // step, its partial repeat and the rest (issue #11 item 6: 7 fewer right-hand sides per
      // switch on the bicycle's RK4 runs, and no cosine per step).
      if (!k1_now) {
        calc_acceleration(m, ws, q0, v0, k1_own[0], k1_own[1]);
        k1_now = k1_own;
      }
      int after[32];
      double angle = 0.0, reach = 0.0;
      const double tau = predict_switch(m, ws, q0, v0, k1_now[0], remaining, ng, after, angle, reach);
      if (tau < remaining * (1 - 1e-12)) {
        rk4(m, ws, tau, k1_now);
        remaining -= tau;
        // The switch stands where the step reached its angle, or fell short of it by at most
        // 1e-4 of the step's travel (the linear estimate it replaces was off by ~1e-3). A path
        // that fell further short (the Taylor path overshot: strongly varying q̈ over a long
        // step) has not switched: the next pass predicts again from here, closer, or finds the
        // angle beyond the step.
        const double short_by = (v0 > 0 ? 1.0 : -1.0) * (angle - ws.q);
        if (short_by <= 1e-4 * reach) {
          if (std::isnan(t_first)) t_first = ws.t;
          for (size_t g = 0; g < ng; ++g)
            if (after[g] >= 0) ws.gate_on[g] = static_cast<char>(after[g]);
        }
        continue;
      }
    }
    rk4(m, ws, remaining, k1_now);
    // The check at the step's end: every gate agrees with its switching function's sign there,
    // or the step is split where the first disagreeing one crossed zero.
    double fr[32];
    const double frac = gates_agree_by_sign(m, ws, ng) ? 2.0 : first_switch_fraction(m, ws, q0, v0, ng, fr);
    if (frac > 1.0) {
      remaining = 0.0;  // the step to the end stands
      agreed_at_end = true;
      break;
    }
    ws.q = q0, ws.qdot = v0, ws.t = t0, ws.work = w0;
    const double h1 = std::max(0.0, std::min(1.0, frac)) * remaining;
    if (h1 > 0) rk4(m, ws, h1, k1_now);
    if (std::isnan(t_first)) t_first = ws.t;
    for (size_t g = 0; g < ng; ++g)
      if (fr[g] <= frac + 1e-9) ws.gate_on[g] = !ws.gate_on[g];
    remaining -= h1;
  }
  // Gates still disagreeing after 8 splits chatter: a load whose switching drives its own
  // switching function back through zero (sliding). Time must still advance by h, so the rest
  // of the step runs with the gates as they now are.
  if (remaining > 0) rk4(m, ws, remaining);
  if (agreed_at_end && all_predictable) mark_ahead(m, ws, ng);
  else ws.ahead_q = NAN;
  return t_first;
}

std::string describe_q(bool revolute, double q, int digits) {
  return revolute ? fmt::format("q = {:.{}g}°", q * 180 / M_PI, digits) : fmt::format("q = {:.{}g} m", q, digits);
}

}  // namespace rdyn::reduced
