#include "engine/reduced_source.hpp"

#include <cmath>

#include <fmt/format.h>

#include "engine/full_model_impl.hpp"
#include "engine/independent_range.hpp"
#include "engine/kinetostatic.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {
// Continuation moves of at most 10° (with the secant predictor; retried in 2° and 0.2° moves
// when a projection fails).
constexpr double kMaxJump = 10.0 * 3.14159265358979323846 / 180.0;
// Continuation moves one approach may take: a revolute coordinate never walks more than half a
// turn (900 of the finest 0.2° moves); for a prismatic one the jumps are read in metres
// (0.17 m, finest 3.5 mm), so 1e4 finest moves are 35 m of stroke. More means a runaway target
// (a huge or non-finite request), refused rather than walked.
constexpr double kMaxApproachMoves = 10000;
}

FullKinetostaticSource::FullKinetostaticSource(const FullModel& model, bool wrap_turns)
    : model_(model),
      ws_(model),
      wrap_turns_(wrap_turns),
      // A prismatic coordinate moves in metres: 10° read as 0.17 m could cross a whole stroke.
      max_jump_(model.scene().find_joint(model.scene().independent)->type == models::JointType::Revolute
                    ? kMaxJump
                    : calc_length_scale(model.scene()) / 20),
      q_now_(model.scene().initial.q) {}

int FullKinetostaticSource::num_constraint_forces() const {
  return static_cast<int>(model_.scene().outputs.constraint_forces.size());
}
int FullKinetostaticSource::num_joints() const { return static_cast<int>(model_.scene().joints.size()); }

template <typename F>
auto FullKinetostaticSource::at(double q, F&& call, bool from_anchor) {
  const double q_start = q_now_;
  const Vector q_backup = ws_.impl().state.getQ();  // the last good configuration
  for (double jump : {max_jump_, max_jump_ / 5, max_jump_ / 50}) {
    try {
      // Retries walk from the last good configuration in finer moves, without the predictor.
      approach(q, jump, from_anchor && jump == max_jump_);
      ++calls_;
      return call();
    } catch (const EngineError& e) {
      if (jump == max_jump_ / 50) {
        const auto& sc = model_.scene();
        const bool rev = sc.find_joint(sc.independent)->type == models::JointType::Revolute;
        const double k = rev ? 180.0 / M_PI : 1.0;
        throw EngineError(fmt::format(
            "{}: the independent coordinate '{}' cannot move from {:.6g} to {:.6g} {}: a dead point of the mechanism "
            "lies in between (the loops cannot close beyond it). A reduced table's range must lie between the "
            "mechanism's dead points: declare independent_range inside them, or leave it out and rdyn finds them. ({})",
            sc.source_file, sc.independent, q_start * k, q * k, rev ? "degrees" : "m", describe_simbody_exception(e)));
      }
      ws_.impl().state.updQ() = q_backup;  // back to the last good configuration
      q_now_ = q_start;
    }
  }
  throw EngineError("unreachable");
}

void FullKinetostaticSource::approach(double q, double max_jump, bool from_anchor) {
  const auto& jt = *model_.scene().find_joint(model_.scene().independent);
  const bool turns = jt.type == models::JointType::Revolute && wrap_turns_;
  extrapolation_ = 0.0;
  if (from_anchor && anchor_) {
    const double d = turns ? std::remainder(q - *anchor_, 2 * M_PI) : q - *anchor_;
    if (std::abs(d) <= max_jump * (1 + 1e-9)) {
      extrapolation_ = max_jump * (1 + 1e-9);
      q_now_ = q;
      return;
    }
  }
  // A revolute independent coordinate repeats the configuration every turn: walk to the
  // periodic image of q nearest the current configuration, then the call itself prescribes q
  // (the same configuration; the projection only relabels the angle).
  double target = q;
  if (turns) target = q + 2 * M_PI * std::round((q_now_ - q) / (2 * M_PI));
  const double moves = std::ceil(std::abs(target - q_now_) / max_jump - 1e-9);
  if (!(moves <= kMaxApproachMoves))  // also NaN
    throw models::NumericalError(fmt::format(
        "{}: continuation from {} = {:.6g} to {:.6g} would need {:.3g} moves of {:.3g} (limit {:g})",
        model_.scene().source_file, model_.scene().independent, q_now_, q, moves, max_jump, kMaxApproachMoves));
  const int steps = static_cast<int>(moves);
  for (int i = 1; i < steps; ++i) {
    move_configuration(model_, ws_, q_now_ + (target - q_now_) * i / steps);
    ++calls_;
  }
  q_now_ = q;
}

reduced::ForcePoint FullKinetostaticSource::inertial(double q, double qdot, double qddot) {
  return at(q, [&] {
    const auto r = calc_kinetostatic(model_, ws_, q, qdot, qddot, Loads::Off);
    return reduced::ForcePoint{r.driving_force, r.constraint_forces, r.joint_u};
  });
}

reduced::GridSample FullKinetostaticSource::sample(double q, bool with_conservative) {
  if (model_.options().route != ConstraintForceRoute::Actuator && num_constraint_forces() > 0)
    return at(q, [&] { return sample_here(q, with_conservative); });
  auto g = at(q, [&] { return sample_fast(q, with_conservative); }, true);
  anchor_ = q;
  return g;
}

reduced::GridSample FullKinetostaticSource::sample_fast(double q, bool with_conservative) {
  const long singular_before = ws_.impl().near_singular_projections;
  const auto k = calc_kinetostatic_sample(model_, ws_, q, extrapolation_, SampleParts::All);
  reduced::GridSample g;
  g.velocity = {k.m2, k.me2, k.ratio_q};
  g.acceleration = {k.m1, k.me1, {}};
  g.ratios = {k.ratio_q, k.ratio_x, k.joint_q, k.ratio_slope, k.length_wrt_q, k.length_wrt_x};
  if (with_conservative) {
    // The static call at the same configuration (its projection only checks the loops).
    const auto c = calc_kinetostatic(model_, ws_, q, 0, 0, Loads::Conservative);
    g.conservative = {{c.driving_force, c.constraint_forces, {}}, c.potential_energy};
  } else {
    g.conservative.forces.constraint_forces.assign(num_constraint_forces(), 0.0);
  }
  // Singular configuration: as sample_here.
  g.singular = ws_.impl().near_singular_projections > singular_before || k.conditioning < kSingularConditioning;
  g.conditioning = k.conditioning;
  return g;
}

reduced::GridSample FullKinetostaticSource::sample_here(double q, bool with_conservative) {
  const long singular_before = ws_.impl().near_singular_projections;
  reduced::GridSample g;
  // (i) q̇ = 1, q̈ = 0: its joint rates are the velocity ratios wrt q (x fixed).
  const auto vel = calc_kinetostatic(model_, ws_, q, 1.0, 0.0, Loads::Off);
  g.velocity = {vel.driving_force, vel.constraint_forces, vel.joint_u};
  g.ratios.wrt_q = vel.joint_u;
  g.ratios.length_wrt_q = vel.point_force_rate;  // L̇ at q̇ = 1: dL/dq
  // (ii) q̇ = 0, q̈ = 1.
  const auto acc = calc_kinetostatic(model_, ws_, q, 0.0, 1.0, Loads::Off);
  g.acceleration = {acc.driving_force, acc.constraint_forces, acc.joint_u};
  if (with_conservative) {
    const auto c = calc_kinetostatic(model_, ws_, q, 0, 0, Loads::Conservative);
    g.conservative = {{c.driving_force, c.constraint_forces, {}}, c.potential_energy};
  } else {
    g.conservative.forces.constraint_forces.assign(num_constraint_forces(), 0.0);
  }
  auto vx = calc_velocity_ratios(model_, ws_, q, false, true);
  g.ratios.wrt_x = std::move(vx.wrt_x);
  g.ratios.length_wrt_x = std::move(vx.length_wrt_x);
  g.ratios.joint_q = vel.joint_q;
  // Singular configuration: the loop Jacobian lost rank (or the projection needed its
  // fallback tolerance). The constraints do not determine the velocities there.
  g.singular = ws_.impl().near_singular_projections > singular_before ||
               calc_loop_conditioning(model_, ws_) < kSingularConditioning;
  return g;
}

double FullKinetostaticSource::ratio(double q, int joint) {
  return at(q, [&] { return calc_velocity_ratios(model_, ws_, q, true, false).wrt_q[joint]; });
}

std::optional<std::pair<double, double>> FullKinetostaticSource::ratio_and_slope(double q, int joint) {
  return at(
      q,
      [&] {
        const auto k = calc_kinetostatic_sample(model_, ws_, q, extrapolation_, SampleParts::RatesOnly);
        return std::optional<std::pair<double, double>>({k.ratio_q[joint], k.ratio_slope[joint]});
      },
      true);
}

std::optional<double> FullKinetostaticSource::joint_coordinate(double q, int joint) {
  // A position projection only (the sweep already stands at q, so it is one Newton solve).
  return at(q, [&] {
    move_configuration(model_, ws_, q);
    return model_.impl().joint_q(ws_.impl().state, joint);
  });
}

reduced::ConservativePoint FullKinetostaticSource::conservative(double q) {
  return at(q, [&] {
    const auto r = calc_kinetostatic(model_, ws_, q, 0, 0, Loads::Conservative);
    return reduced::ConservativePoint{{r.driving_force, r.constraint_forces, {}}, r.potential_energy};
  });
}

reduced::RatioPoint FullKinetostaticSource::ratios(double q) {
  return at(q, [&] {
    const auto v = calc_velocity_ratios(model_, ws_, q);
    std::vector<double> joint_q(model_.scene().joints.size());
    for (size_t j = 0; j < joint_q.size(); ++j) joint_q[j] = model_.impl().joint_q(ws_.impl().state, static_cast<int>(j));
    return reduced::RatioPoint{v.wrt_q, v.wrt_x, joint_q, {}, v.length_wrt_q, v.length_wrt_x};
  });
}

std::optional<reduced::ForcePoint> FullKinetostaticSource::harmonic_sweep(const double c[5], double t) {
  const double q = c[0] + c[1] * t + c[2] * std::cos(c[3] * t + c[4]);
  return at(q, [&] {
    const auto r = calc_harmonic_sweep_point(model_, ws_, c, t, Loads::Off);
    return std::optional<reduced::ForcePoint>(reduced::ForcePoint{r.driving_force, r.constraint_forces, {}});
  });
}

std::optional<reduced::DirectPoint> FullKinetostaticSource::direct(double q) {
  return at(q, [&] { return direct_here(q); });
}

std::optional<reduced::DirectPoint> FullKinetostaticSource::direct_here(double q) {
  const auto& m = model_.impl();
  State& s = ws_.impl().state;
  const int nx = num_constraint_forces();
  // Mobility-space velocity-ratio vectors: u (q̇ = 1, x fixed) and u_x,k (ẋ_k = 1, q̇ = 0).
  std::vector<Vector> ux;
  for (int k = 0; k < nx; ++k) {
    s.setTime(0);
    m.set_law(s, 0, poly_law(q, 0, 0));
    for (int i = 0; i < nx; ++i) m.set_law(s, 1 + i, poly_law(0, i == k ? 1.0 : 0.0, 0));
    m.system.realize(s, Stage::Time);
    m.system.project(s, 1e-12);
    ux.push_back(s.getU());
  }
  // u and the bias acceleration b (q̈ = 0 at q̇ = 1), then M u and M b + c(q, u).
  calc_kinetostatic(model_, ws_, q, 1.0, 0.0, Loads::Off);
  m.system.realize(s, Stage::Acceleration);
  const Vector u = s.getU(), b = s.getUDot();
  Vector Mu, residual;
  m.matter.multiplyByM(s, u, Mu);
  m.matter.calcResidualForceIgnoringConstraints(s, Vector(), Vector_<SpatialVec>(), b, residual);
  reduced::DirectPoint d;
  d.m1 = ~u * Mu;        // T = ½ m1 q̇²
  d.m2 = ~u * residual;  // uᵀ(M b + c)
  bool finite = std::isfinite(d.m1) && std::isfinite(d.m2);
  for (int k = 0; k < nx; ++k) {
    d.me1.push_back(~ux[k] * Mu);
    d.me2.push_back(~ux[k] * residual);
    finite &= std::isfinite(d.me1.back()) && std::isfinite(d.me2.back());
  }
  if (!finite)
    throw models::NumericalError(fmt::format("{}: non-finite reduced parameters at {} = {:.6g}",
                                             model_.scene().source_file, model_.scene().independent, q));
  return d;
}

}  // namespace rdyn::engine
