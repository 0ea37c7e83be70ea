#include "engine/kinetostatic.hpp"
#include "engine/independent_range.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>

#include <fmt/format.h>

#include "engine/branch_rates.hpp"
#include "engine/full_model_impl.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

LoadMode mode_of(Loads l) {
  return l == Loads::Off ? kLoadsOff : l == Loads::Conservative ? kLoadsConservative : kLoadsInstant;
}

// Secant predictor: extrapolate every coordinate along the branch from the last two
// converged configurations to the new value of the independent coordinate (a revolute one is
// compared modulo a turn, since continuation relabels the angle by 2π).
void predict(FullWorkspace::Impl& w, double q_new) {
  if (w.hist_n < 2) return;
  const auto& m = w.model;
  const bool revolute = m.scene.joints[m.independent].type == models::JointType::Revolute;
  auto wrap = [&](double d) { return revolute ? std::remainder(d, 2 * M_PI) : d; };
  const double d_last = wrap(w.hist_x[1] - w.hist_x[0]);
  const double d_new = wrap(q_new - w.hist_x[1]);
  if (std::abs(d_last) < 1e-9 || std::abs(d_new) < 1e-12 || std::abs(d_new) > 4 * std::abs(d_last) + 0.2) return;
  const Vector& q1 = w.hist_q[1];
  const Vector& q0 = w.hist_q[0];
  if (q1.size() != w.state.getNQ() || q0.size() != q1.size()) return;
  Vector pred = q1 + (q1 - q0) * (d_new / d_last);
  w.state.updQ() = pred;
}

void remember(FullWorkspace::Impl& w, double q) {
  const bool revolute = w.model.scene.joints[w.model.independent].type == models::JointType::Revolute;
  const double d = revolute ? std::remainder(q - w.hist_x[1], 2 * M_PI) : q - w.hist_x[1];
  if (w.hist_n > 0 && std::abs(d) < 1e-9) {  // same point again: refresh it
    w.hist_q[1] = w.state.getQ();
    w.hist_x[1] = q;
    return;
  }
  w.hist_q[0] = w.hist_q[1];
  w.hist_x[0] = w.hist_x[1];
  w.hist_q[1] = w.state.getQ();
  w.hist_x[1] = q;
  w.hist_n = std::min(w.hist_n + 1, 2);
}

// Applies the prescribed laws (already stored in the workspace's state) and projects q and u onto
// the constraint manifold, starting from the predicted configuration; counts the fallbacks.
void project(FullWorkspace::Impl& w, double q_for_message) {
  const auto& m = w.model;
  State& s = w.state;
  try {
    m.system.realize(s, Stage::Time);
    try {
      m.system.project(s, 1e-12);
    } catch (const std::exception&) {
      // At a singular configuration (e.g. a parallelogram's aligned position) the constraint
      // Jacobian loses rank and the projection stalls a little above 1e-12; accept 1e-9 there.
      m.system.project(s, 1e-9);
      ++w.near_singular_projections;
    }
  } catch (const std::exception& e) {
    throw EngineError(fmt::format("{}: cannot reach {} = {:.6g} from the previous configuration "
                                  "(dead point or a loop that cannot close): {}",
                                  m.scene.source_file, m.scene.independent, q_for_message,
                                  describe_simbody_exception(e)));
  }
}

// L̇ of every point force's line at a state realized to Velocity [m/s]. A line shorter than the
// limit has no direction: NumericalError naming the load and q.
std::vector<double> point_force_rates(const FullModel::Impl& m, const State& s) {
  std::vector<double> out;
  for (const auto& f : m.scene.point_forces) {
    const auto line = calc_point_force_line(m, s, f, true);
    if (!(line.length >= models::limits::kMinPointForceLength_m) || !std::isfinite(line.rate))
      throw models::PointForceMeeting(
          fmt::format("{}: point force '{}' has its points {:.3g} m apart at {} = {:.6g}: its line of action has no "
                      "direction there",
                      m.scene.source_file, f.name, line.length, m.scene.independent, m.joint_q(s, m.independent)),
          m.joint_q(s, m.independent), f.name);
    out.push_back(line.rate);
  }
  return out;
}

KinetostaticResult collect(const FullModel::Impl& m, const State& s) {
  m.system.realize(s, Stage::Acceleration);
  KinetostaticResult r;
  // Motion multipliers sit on the left (M u̇ + Gᵀλ + τ = f): the actuator supplies −τ.
  r.driving_force = -m.joint_mobod[m.independent].getOneTau(s, MobilizerUIndex(0));
  r.constraint_forces = m.constraint_forces(s);
  const size_t nj = m.scene.joints.size();
  r.joint_q.resize(nj);
  r.joint_u.resize(nj);
  for (size_t j = 0; j < nj; ++j) {
    r.joint_q[j] = m.joint_q(s, static_cast<int>(j));
    r.joint_u[j] = m.joint_u(s, static_cast<int>(j));
  }
  r.point_force_rate = point_force_rates(m, s);
  r.kinetic_energy = m.system.calcKineticEnergy(s);
  // Folded bodies: ½ r² I u² is already in the driver's inertia.
  r.potential_energy = m.system.calcPotentialEnergy(s);
  // Simbody does not throw on NaN or inf (e.g. a mass matrix made singular by a degenerate
  // geometry): nothing non-finite leaves the engine.
  bool finite = std::isfinite(r.driving_force) && std::isfinite(r.kinetic_energy) &&
                std::isfinite(r.potential_energy);
  for (double f : r.constraint_forces) finite &= std::isfinite(f);
  for (size_t j = 0; j < nj; ++j) finite &= std::isfinite(r.joint_q[j]) && std::isfinite(r.joint_u[j]);
  if (!finite)
    throw models::NumericalError(fmt::format("{}: the full model returned a non-finite force, energy or joint "
                                             "state at {} = {:.6g}",
                                             m.scene.source_file, m.scene.independent,
                                             m.joint_q(s, m.independent)));
  return r;
}

// Prescribed values must be finite before Simbody sees them (a NaN law would project to NaN).
void check_finite_input(const FullModel::Impl& m, std::initializer_list<double> values) {
  for (double v : values)
    if (!std::isfinite(v))
      throw models::NumericalError(fmt::format("{}: non-finite value prescribed to the independent coordinate '{}'",
                                               m.scene.source_file, m.scene.independent));
}

void ensure_kinetostatic_mode(const FullModel::Impl& m, State& s) {
  if (m.independent_motion.isDisabled(s)) {
    m.independent_motion.enable(s);
    m.system.realizeModel(s);
  }
}

}  // namespace

KinetostaticResult calc_kinetostatic(const FullModel& model, FullWorkspace& ws, double q, double qdot,
                                     double qddot, Loads loads) {
  const auto& m = model.impl();
  check_finite_input(m, {q, qdot, qddot});
  State& s = ws.impl().state;
  ensure_kinetostatic_mode(m, s);
  s.setTime(0.0);
  m.set_law(s, 0, poly_law(q, qdot, qddot));
  for (size_t k = 0; k < m.actuator_slider.size(); ++k) m.set_law(s, 1 + static_cast<int>(k), poly_law(0, 0, 0));
  m.set_load_mode(s, mode_of(loads));
  project(ws.impl(), q);
  return collect(m, s);
}

std::vector<double> calc_joint_output_row(const FullModel& model, FullWorkspace& ws) {
  const auto& m = model.impl();
  const State& s = ws.impl().state;
  m.system.realize(s, Stage::Acceleration);
  std::vector<double> out;
  calc_joint_outputs(m, s, out);
  return out;
}

void move_configuration(const FullModel& model, FullWorkspace& ws, double q) {
  const auto& m = model.impl();
  check_finite_input(m, {q});
  State& s = ws.impl().state;
  ensure_kinetostatic_mode(m, s);
  s.setTime(0.0);
  m.set_law(s, 0, poly_law(q, 0.0, 0.0));
  predict(ws.impl(), q);
  try {
    m.system.realize(s, Stage::Time);
    m.system.prescribeQ(s);
    m.system.projectQ(s, 1e-12);
    remember(ws.impl(), q);
  } catch (const std::exception& e) {
    throw EngineError(fmt::format("{}: cannot reach {} = {:.6g} from the previous configuration "
                                  "(dead point or a loop that cannot close): {}",
                                  m.scene.source_file, m.scene.independent, q, describe_simbody_exception(e)));
  }
}

VelocityRatios calc_velocity_ratios(const FullModel& model, FullWorkspace& ws, double q, bool with_q, bool with_x) {
  const auto& m = model.impl();
  check_finite_input(m, {q});
  State& s = ws.impl().state;
  ensure_kinetostatic_mode(m, s);
  s.setTime(0.0);
  const size_t nj = m.scene.joints.size(), nx = m.actuator_slider.size();
  auto rates = [&] {
    std::vector<double> u(nj);
    for (size_t j = 0; j < nj; ++j) {
      u[j] = m.joint_u(s, static_cast<int>(j));
      if (!std::isfinite(u[j]))
        throw models::NumericalError(fmt::format("{}: non-finite velocity ratio of joint '{}' at {} = {:.6g}",
                                                 m.scene.source_file, m.scene.joints[j].name, m.scene.independent, q));
    }
    return u;
  };
  VelocityRatios out;
  if (with_q) {
    m.set_law(s, 0, poly_law(q, 1.0, 0.0));
    for (size_t k = 0; k < nx; ++k) m.set_law(s, 1 + static_cast<int>(k), poly_law(0, 0, 0));
    project(ws.impl(), q);
    out.wrt_q = rates();
    m.system.realize(s, Stage::Velocity);
    out.length_wrt_q = point_force_rates(m, s);
  }
  for (size_t k = 0; k < nx && with_x; ++k) {
    m.set_law(s, 0, poly_law(q, 0.0, 0.0));
    for (size_t i = 0; i < nx; ++i) m.set_law(s, 1 + static_cast<int>(i), poly_law(0, i == k ? 1.0 : 0.0, 0));
    project(ws.impl(), q);
    out.wrt_x.push_back(rates());
    m.system.realize(s, Stage::Velocity);
    out.length_wrt_x.push_back(point_force_rates(m, s));
  }
  for (size_t i = 0; i < nx; ++i) m.set_law(s, 1 + static_cast<int>(i), poly_law(0, 0, 0));
  return out;
}


void follow_branch(const FullModel& model, FullWorkspace& ws, double q, double max_step, double max_correction) {
  const auto& m = model.impl();
  check_finite_input(m, {q, max_step, max_correction});
  auto& w = ws.impl();
  State& s = w.state;
  ensure_kinetostatic_mode(m, s);
  s.setTime(0.0);
  for (size_t k = 0; k < m.actuator_slider.size(); ++k) m.set_law(s, 1 + static_cast<int>(k), poly_law(0, 0, 0));
  m.system.realize(s, Stage::Position);
  double x = m.joint_q(s, m.independent);
  if (w.hist_n == 0) remember(w, x);
  // The smallest move before a correction larger than max_correction is accepted anyway (a
  // configuration where the branch turns within 1e-6 of a move: no better prediction exists).
  const double min_step = 1e-6 * max_step;
  constexpr long kMaxMoves = 100000;
  double step = max_step;
  for (long moves = 0; x != q; ++moves) {
    if (moves > kMaxMoves)
      throw EngineError(fmt::format("{}: the branch continuation to {} = {:.6g} needed more than {} moves",
                                    m.scene.source_file, m.scene.independent, q, kMaxMoves));
    // Second-order predictor along the branch; at a singular configuration the chord of the
    // last move instead (the branch the continuation came along; calc_kinetostatic_sample's rule).
    BranchTangent t = calc_branch_tangent(m, s, x);
    if (t.singular && w.hist_n == 2 && std::abs(w.hist_x[1] - w.hist_x[0]) > 1e-12 &&
        w.hist_q[0].size() == s.getNQ()) {
      t.dq = (w.hist_q[1] - w.hist_q[0]) / (w.hist_x[1] - w.hist_x[0]);
      t.ddq = 0.0 * t.dq;
    }
    const Vector q_here = s.getQ();
    double d = std::clamp(q - x, -step, step);
    for (;;) {
      const double x_new = std::abs(q - x) <= std::abs(d) ? q : x + d;
      d = x_new - x;
      const Vector pred = q_here + t.dq * d + t.ddq * (0.5 * d * d);
      s.updQ() = pred;
      m.set_law(s, 0, poly_law(x_new, 0.0, 0.0));
      bool converged = true;
      try {
        project_prescribed(w);
      } catch (const std::exception&) {
        converged = false;
      }
      // Newton's correction of the prediction: O(d³) on this branch; a move that lands on
      // another branch nearby (where two branches pass close, the one followed turning sharply)
      // is corrected by the prediction's distance to it, larger than this for a long enough move.
      double correction = 0.0;
      if (converged)
        for (int i = 0; i < s.getNQ(); ++i) correction = std::max(correction, std::abs(s.getQ()[i] - pred[i]));
      const bool accept = converged && std::isfinite(correction) && correction <= max_correction;
      if (accept || std::abs(d) <= min_step) {
        if (!converged)
          throw EngineError(fmt::format("{}: cannot reach {} = {:.6g} from the previous configuration "
                                        "(dead point or a loop that cannot close)",
                                        m.scene.source_file, m.scene.independent, x_new));
        x = x_new;
        remember(w, x);
        step = std::min(max_step, 2 * std::abs(d));  // grow back after a turn
        break;
      }
      d *= 0.5;
    }
  }
  m.system.realize(s, Stage::Position);
}

double calc_loop_conditioning(const FullModel& model, FullWorkspace& ws) {
  return calc_loop_conditioning(model.impl(), ws.impl().state);
}

double calc_loop_conditioning(const FullModel::Impl& m, const State& s) {
  m.system.realize(s, Stage::Position);
  const auto J = calc_split_jacobian(m, s);
  if (J.G.nrow() == 0) return 1.0;
  return calc_conditioning(J.G_free);
}

namespace {

// Stage 1 of a sample: call (i)'s laws (q̇ = 1, q̈ = 0, loads off, every actuator at
// x = ẋ = ẍ = 0) and the starting configuration of the projection. From the anchor (the last
// grid point of this workspace) a second-order predictor along the branch, so Newton starts
// O(Δ³) from the solution; without one (or beyond max_extrapolation) the configuration the
// sample starts from — the assembly or the last continuation move.
void start_sample(const FullModel::Impl& m, FullWorkspace::Impl& w, double q, double max_extrapolation) {
  State& s = w.state;
  ensure_kinetostatic_mode(m, s);
  s.setTime(0.0);
  m.set_law(s, 0, poly_law(q, 1.0, 0.0));
  for (size_t k = 0; k < m.actuator_slider.size(); ++k) m.set_law(s, 1 + static_cast<int>(k), poly_law(0, 0, 0));
  m.set_load_mode(s, kLoadsOff);
  if (w.anchor_set && w.anchor_q.size() == s.getNQ()) {
    const bool revolute = m.scene.joints[m.independent].type == models::JointType::Revolute;
    const double d = revolute ? std::remainder(q - w.anchor_x, 2 * M_PI) : q - w.anchor_x;
    if (std::abs(d) <= max_extrapolation) s.updQ() = w.anchor_q + w.anchor_dq * d + w.anchor_ddq * (0.5 * d * d);
  }
}

// Stage 2: the Newton projection of the loops, the only iterative step (velocities and
// accelerations follow from linear solves with the Jacobian at the converged configuration).
void project_sample(const FullModel::Impl& m, FullWorkspace::Impl& w, double q) {
  try {
    project_prescribed(w);
  } catch (const std::exception& e) {
    throw EngineError(fmt::format("{}: cannot reach {} = {:.6g} from the previous configuration "
                                  "(dead point or a loop that cannot close): {}",
                                  m.scene.source_file, m.scene.independent, q, describe_simbody_exception(e)));
  }
  m.system.realize(w.state, Stage::Position);
}

// Stage 3: r (q̇ = 1, ẋ = 0: the velocity projection of call (i)) and b = dr/dq (its
// accelerations) from the Jacobian of this configuration (calc_branch_rates); the state is left
// at u = r. Near a singular configuration, not on it (there the rates are repaired, not
// computed), the projection is polished to rounding and the rates computed again
// (polish_projection). Returns the rates used; `conditioning` is theirs.
BranchRates& calc_sample_rates(const FullModel::Impl& m, State& s, BranchRates& first,
                               std::optional<BranchRates>& polished, double& conditioning) {
  calc_branch_rates(m, s, first);
  conditioning = first.conditioning;
  if (conditioning < kSingularConditioning || conditioning >= kPolishConditioning) return first;
  polish_projection(m, s);
  calc_branch_rates(m, s, polished.emplace());
  conditioning = polished->conditioning;
  return *polished;
}

// Stage 4: every joint's coordinate, rate per unit q̇ and the rate's slope. Returns false when
// one is not finite.
bool fill_joint_rates(const FullModel::Impl& m, const State& s, const Vector& u, const Vector& b,
                      KinetostaticSample& out) {
  const int nj = static_cast<int>(m.scene.joints.size());
  out.joint_q.resize(nj);
  out.ratio_q.resize(nj);
  out.ratio_slope.resize(nj);
  bool finite = true;
  for (int j = 0; j < nj; ++j) {
    out.joint_q[j] = m.joint_q(s, j);
    out.ratio_q[j] = joint_part(m, s, u, j);
    out.ratio_slope[j] = joint_part(m, s, b, j);
    finite &= std::isfinite(out.joint_q[j]) && std::isfinite(out.ratio_q[j]) && std::isfinite(out.ratio_slope[j]);
  }
  return finite;
}

// aᵀb summed in SimTK's order (its RowVector × Vector: from 0, j = 0, 1, …), the same bits
// without the transposed view's element calls (~2 k instructions each, four a sample).
double dot_product(const Vector& a, const Vector& b) {
  double sum = 0.0;
  for (int j = 0; j < a.size(); ++j) sum += a[j] * b[j];
  return sum;
}

// Stage 5 (a grid point): the reduced parameters by virtual power with r and r_x,k (both satisfy
// G v = 0, zero on the other prescribed mobilities), loads off, M u̇ + c + Gᵀλ + τ = 0 and the
// actuators supplying −τ: call (i): m2 = rᵀ(M b + c), me2_k = r_x,kᵀ(M b + c); call (ii), where
// q̇ = 0 and u̇ = r: m1 = rᵀ M r, me1_k = r_x,kᵀ M r. Also L̇ of every point force at ẋ_k = 1 (the
// state's velocities are not used again). Returns false when a value is not finite.
bool fill_inertial_parameters(const FullModel::Impl& m, State& s, BranchRates& rates, KinetostaticSample& out) {
  const Vector &u = rates.r, &b = rates.b;
  const int nj = static_cast<int>(m.scene.joints.size()), nx = static_cast<int>(m.actuator_slider.size());
  Vector Mr, inertial;
  m.matter.multiplyByM(s, u, Mr);
  static const Vector kNoForces;                  // immutable: safe to share between threads
  static const Vector_<SpatialVec> kNoBodyForces;
  m.matter.calcResidualForceIgnoringConstraints(s, kNoForces, kNoBodyForces, b, inertial);  // M b + c
  out.m1 = dot_product(u, Mr);
  out.m2 = dot_product(u, inertial);
  bool finite = std::isfinite(out.m1) && std::isfinite(out.m2);
  for (int k = 0; k < nx; ++k) {
    // r_x,k: ẋ_k = 1, q̇ = 0, the other x fixed.
    const int col = m.actuator_slider[k].getFirstUIndex(s);
    Vector rx(s.getNU(), 0.0);
    rx[col] = 1.0;
    rates.complete(rx, rates.column(col));
    std::vector<double> ratio(nj);
    for (int j = 0; j < nj; ++j) finite &= std::isfinite(ratio[j] = joint_part(m, s, rx, j));
    out.ratio_x.push_back(std::move(ratio));
    out.me1.push_back(dot_product(rx, Mr));
    out.me2.push_back(dot_product(rx, inertial));
    if (!m.scene.point_forces.empty()) {
      s.updU() = rx;
      m.system.realize(s, Stage::Velocity);
      out.length_wrt_x.push_back(point_force_rates(m, s));
    } else {
      out.length_wrt_x.emplace_back();
    }
    finite &= std::isfinite(out.me1.back()) && std::isfinite(out.me2.back());
  }
  return finite;
}

// Stage 6 (a grid point): this point anchors the next prediction: q' = N r, q'' = N b (Ṅ = 0 for
// the pins and sliders rdyn builds). At a singular configuration r and b are least-squares
// values of no particular branch (a parallelogram's aligned position, where the
// antiparallelogram branch crosses): extrapolating along them led the next projection onto the
// other branch (the hard parallelogram's table turned antiparallelogram after 180°, and its
// reduced run diverged). There the prediction follows the chord from the previous grid point
// instead, the branch the sweep came along (positions are determined at the singular point;
// only the rates are not). (q_start, x_start): the configuration the sample started from.
void update_anchor(const FullModel::Impl& m, FullWorkspace::Impl& w, double q, const BranchRates& rates,
                   bool singular, const Vector& q_start, double x_start, double max_extrapolation) {
  State& s = w.state;
  const bool revolute = m.scene.joints[m.independent].type == models::JointType::Revolute;
  Vector q_before;
  double x_before = 0.0;
  const bool had_anchor = w.anchor_set && w.anchor_q.size() == s.getNQ();
  if (had_anchor) q_before = w.anchor_q, x_before = w.anchor_x;
  w.anchor_set = true;
  w.anchor_x = q;
  w.anchor_q = s.getQ();
  if (m.jacobian_plan) {  // only pins and sliders: N = I, its product a copy (~3 k instructions each)
    w.anchor_dq = rates.r;
    w.anchor_ddq = rates.b;
  } else {
    m.matter.multiplyByN(s, false, rates.r, w.anchor_dq);
    m.matter.multiplyByN(s, false, rates.b, w.anchor_ddq);
  }
  double dx = q - x_before;  // unwrapped: a relabelled turn between the two gives no chord
  // How far a chord may reach: two extrapolation lengths from the previous grid point; from the
  // start, wherever it was (the first grid point is the one nearest the start, and the first
  // call has no extrapolation length yet).
  double chord_limit = 2 * max_extrapolation;
  if (singular && !had_anchor && q_start.size() == s.getNQ()) {
    // The first grid point: the chord from the configuration the sample started from.
    q_before = q_start;
    dx = revolute ? std::remainder(q - x_start, 2 * M_PI) : q - x_start;
    chord_limit = INFINITY;
    // Started on the singular configuration itself: branches cross there and nothing says which
    // one the sweep should follow (a parallelogram started aligned). Bad input, not a failed
    // move to retry.
    if (!(std::abs(dx) > 1e-9)) {
      w.anchor_set = false;
      throw_singular_start(m, s);
    }
  }
  if (singular && q_before.size() == s.getNQ() && std::abs(dx) > 1e-9 && std::abs(dx) <= chord_limit) {
    w.anchor_dq = (w.anchor_q - q_before) / dx;
    w.anchor_ddq = 0.0 * w.anchor_dq;
  } else if (singular && had_anchor && q_start.size() == s.getNQ()) {
    // Reached by continuation moves (the anchor lies beyond the chord's reach): the chord from
    // the last move. Without it a prediction from here (the limit samples beside a singular grid
    // point, reduced/extract.cpp) followed least-squares rates onto the other branch on 30° grids.
    const double dm = revolute ? std::remainder(q - x_start, 2 * M_PI) : q - x_start;
    if (std::abs(dm) > 1e-9) {
      w.anchor_dq = (w.anchor_q - q_start) / dm;
      w.anchor_ddq = 0.0 * w.anchor_dq;
    }
  }
}

}  // namespace

KinetostaticSample calc_kinetostatic_sample(const FullModel& model, FullWorkspace& ws, double q,
                                            double max_extrapolation, SampleParts parts) {
  const auto& m = model.impl();
  check_finite_input(m, {q, max_extrapolation});
  if (m.options.route != ConstraintForceRoute::Actuator && !m.scene.outputs.constraint_forces.empty())
    throw EngineError("calc_kinetostatic_sample needs the Actuator constraint-force route");
  auto& w = ws.impl();
  State& s = w.state;
  ensure_kinetostatic_mode(m, s);
  // The configuration before the move gives the direction the sweep comes from, which a
  // singular grid point needs (update_anchor).
  const Vector q_start = s.getQ();
  const double x_start = m.joint_q(s, m.independent);
  start_sample(m, w, q, max_extrapolation);
  const long singular_before = w.near_singular_projections;
  project_sample(m, w, q);
  KinetostaticSample out;
  out.near_singular = w.near_singular_projections > singular_before;
  if (!w.sample_rates) w.sample_rates = std::make_unique<BranchRates>();
  std::optional<BranchRates> polished;  // near a singular configuration only
  double conditioning = 1.0;
  BranchRates& rates = calc_sample_rates(m, s, *w.sample_rates, polished, conditioning);
  bool finite = fill_joint_rates(m, s, rates.r, rates.b, out);
  if (parts == SampleParts::All) {
    out.conditioning = conditioning;
    out.length_wrt_q = point_force_rates(m, s);  // L̇ at q̇ = 1
    finite &= fill_inertial_parameters(m, s, rates, out);
    const bool singular = out.near_singular || out.conditioning < kSingularConditioning;
    update_anchor(m, w, q, rates, singular, q_start, x_start, max_extrapolation);
  }
  if (!finite)
    throw models::NumericalError(fmt::format("{}: the full model returned a non-finite reduced parameter or velocity "
                                             "ratio at {} = {:.6g}",
                                             m.scene.source_file, m.scene.independent, q));
  return out;
}

KinetostaticResult calc_harmonic_sweep_point(const FullModel& model, FullWorkspace& ws, const double c[5],
                                             double t, Loads loads) {
  const auto& m = model.impl();
  check_finite_input(m, {c[0], c[1], c[2], c[3], c[4], t});
  State& s = ws.impl().state;
  ensure_kinetostatic_mode(m, s);
  m.set_law(s, 0, harmonic_law(c[0], c[1], c[2], c[3], c[4]));
  for (size_t k = 0; k < m.actuator_slider.size(); ++k) m.set_law(s, 1 + static_cast<int>(k), poly_law(0, 0, 0));
  m.set_load_mode(s, mode_of(loads));
  s.setTime(t);
  project(ws.impl(), c[0] + c[1] * t + c[2] * std::cos(c[3] * t + c[4]));
  return collect(m, s);
}

}  // namespace rdyn::engine
