// The constraint Jacobian and errors from the configuration (engine/constraint_jacobian.hpp).
#include "engine/constraint_jacobian.hpp"

#include <algorithm>

#include "engine/full_model_impl.hpp"
#include "models/gear_fold.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

// Mobilized bodies from b down to (not including) Ground.
std::vector<MobilizedBodyIndex> path_to_ground(const SimbodyMatterSubsystem& matter, MobilizedBodyIndex b) {
  std::vector<MobilizedBodyIndex> path;
  while (b != GroundIndex) {
    path.push_back(b);
    b = matter.getMobilizedBody(b).getParentMobilizedBody().getMobilizedBodyIndex();
  }
  return path;
}

// The mobilities that move S (on F) but not L: +1; L but not S's body: −1 (both: the relative
// velocity does not see them).
std::vector<std::pair<int, double>> moves_of(const ConstraintJacobianPlan& plan, const SimbodyMatterSubsystem& matter,
                                             MobilizedBodyIndex follower, MobilizedBodyIndex line) {
  const auto pf = path_to_ground(matter, follower), pl = path_to_ground(matter, line);
  auto on = [](const std::vector<MobilizedBodyIndex>& p, MobilizedBodyIndex b) {
    return std::find(p.begin(), p.end(), b) != p.end();
  };
  std::vector<std::pair<int, double>> moves;
  for (size_t k = 0; k < plan.mobilities.size(); ++k) {
    const bool f = on(pf, plan.mobilities[k].body), l = on(pl, plan.mobilities[k].body);
    if (f != l) moves.emplace_back(static_cast<int>(k), f ? 1.0 : -1.0);
  }
  return moves;
}

}  // namespace

std::optional<ConstraintJacobianPlan> make_constraint_jacobian_plan(const FullModel::Impl& m) {
  const State& s = m.default_state();
  ConstraintJacobianPlan plan;
  plan.nu = s.getNU();
  for (int b = 1; b < m.matter.getNumBodies(); ++b) {
    const MobilizedBody& mb = m.matter.getMobilizedBody(MobilizedBodyIndex(b));
    const bool pin = MobilizedBody::Pin::isInstanceOf(mb);
    if (!pin && !MobilizedBody::Slider::isInstanceOf(mb)) return std::nullopt;
    ConstraintJacobianPlan::Mobility mob;
    mob.body = mb.getMobilizedBodyIndex();
    mob.u = mb.getFirstUIndex(s);
    mob.q = mb.getFirstQIndex(s);
    mob.pin = pin;
    // Simbody numbers a body after its parent: the parent's mobility is already listed.
    mob.parent = static_cast<int>(mb.getParentMobilizedBody().getMobilizedBodyIndex()) - 1;
    mob.X_PF = mb.getDefaultInboardFrame();
    mob.X_BM = mb.getDefaultOutboardFrame();
    if (mob.parent >= b - 1) return std::nullopt;
    plan.mobilities.push_back(mob);
  }
  if (static_cast<int>(plan.mobilities.size()) != plan.nu) return std::nullopt;
  // Simbody numbers the holonomic rows constraint by constraint in ConstraintIndex order.
  if (m.matter.getNumConstraints() != static_cast<int>(m.constraints.size())) return std::nullopt;
  size_t gear = 0;
  for (const auto& [name, c] : m.constraints) {
    if (Constraint::PointOnLine::isInstanceOf(c)) {
      const auto& pol = Constraint::PointOnLine::downcast(c);
      ConstraintJacobianPlan::LineRows rows;
      rows.line = pol.getLineMobilizedBodyIndex();
      rows.follower = pol.getFollowerMobilizedBodyIndex();
      rows.point_F = pol.getDefaultFollowerPoint();
      rows.point_L = pol.getDefaultPointOnLine();
      rows.line_mobility = static_cast<int>(rows.line) - 1;
      rows.follower_mobility = static_cast<int>(rows.follower) - 1;
      // As Simbody's PointOnLineImpl::realizeTopologyVirtual picks them.
      const UnitVec3& z = pol.getDefaultLineDirection();
      rows.x_L = z.perp();
      rows.y_L = UnitVec3(z % rows.x_L);
      rows.moves = moves_of(plan, m.matter, rows.follower, rows.line);
      plan.line_of.push_back(static_cast<int>(plan.lines.size()));
      plan.gear_of.push_back(-1);
      plan.lines.push_back(std::move(rows));
      plan.rows += 2;
    } else if (Constraint::CoordinateCoupler::isInstanceOf(c) && gear < m.coupled_gears.size()) {
      const auto& g = m.scene.gears[m.coupled_gears[gear++]];
      const int jr = m.scene.joint_index(g.driver), jd = m.scene.joint_index(g.driven);
      plan.line_of.push_back(-1);
      plan.gear_of.push_back(static_cast<int>(plan.gears.size()));
      plan.gears.push_back({m.joint_mobod[jr].getFirstUIndex(s), m.joint_mobod[jd].getFirstUIndex(s),
                            m.joint_mobod[jr].getFirstQIndex(s), m.joint_mobod[jd].getFirstQIndex(s), g.ratio,
                            models::calc_gear_offset(m.scene, g)});
      plan.rows += 1;
    } else {
      return std::nullopt;
    }
  }
  if (gear != m.coupled_gears.size()) return std::nullopt;
  return plan;
}

const ConstraintJacobianPlan* usable_plan(const FullModel::Impl& m, const State& s) {
  const auto& plan = m.jacobian_plan;
  bool usable = plan && plan->rows == s.getNQErr() && s.getNUErr() == plan->rows && s.getNU() == plan->nu &&
                m.matter.getNumConstraints() == static_cast<int>(m.constraints.size());
  for (size_t c = 0; usable && c < m.constraints.size(); ++c) usable = !m.constraints[c].second.isDisabled(s);
  return usable ? &*plan : nullptr;
}

namespace {

// Rows of G per constraint in Simbody's order, from each mobility's axis and pivot in Ground
// (a pin's M z axis and origin, a slider's M x axis) and, per PointOnLine, the follower point
// S and the line body's rotation in Ground (`line_frame(l)` → {p_S, R_GL}). One formula for
// both routes: the realized State's frames and the frames from q alone.
template <class LineFrame>
void fill_jacobian(const ConstraintJacobianPlan& plan, const std::vector<Vec3>& axis, const std::vector<Vec3>& pivot,
                   const LineFrame& line_frame, Matrix& G) {
  G.resize(plan.rows, plan.nu);
  G = 0.0;
  int row = 0;
  for (size_t c = 0; c < plan.line_of.size(); ++c) {
    if (plan.line_of[c] < 0) {
      const auto& g = plan.gears[plan.gear_of[c]];
      G(row, g.u_driver) += -g.ratio;
      G(row, g.u_driven) += 1.0;
      row += 1;
      continue;
    }
    const auto& l = plan.lines[plan.line_of[c]];
    const auto [p_S, R_GL] = line_frame(l);
    const Vec3 nx = R_GL * l.x_L, ny = R_GL * l.y_L;
    for (const auto& [k, sign] : l.moves) {
      const auto& mob = plan.mobilities[k];
      const Vec3 v = mob.pin ? Vec3(axis[k] % (p_S - pivot[k])) : axis[k];
      G(row, mob.u) += sign * dot(nx, v);
      G(row + 1, mob.u) += sign * dot(ny, v);
    }
    row += 2;
  }
}

// Each mobilized body's X_GB from the coordinates alone: X_GB = X_GP X_PF X_FM(q) X_MB down the
// tree, X_FM a turn about z (pin) or a shift along x (slider).
std::vector<Transform> calc_body_frames(const ConstraintJacobianPlan& plan, const Vector& q) {
  std::vector<Transform> X_GB(plan.mobilities.size());
  for (size_t k = 0; k < plan.mobilities.size(); ++k) {
    const auto& mob = plan.mobilities[k];
    Transform X_FM;  // identity
    if (mob.pin)
      X_FM.updR().setRotationFromAngleAboutZ(q[mob.q]);
    else
      X_FM.updP() = Vec3(q[mob.q], 0, 0);
    const Transform X_GF = mob.parent < 0 ? mob.X_PF : X_GB[mob.parent] * mob.X_PF;
    X_GB[k] = X_GF * X_FM * ~mob.X_BM;
  }
  return X_GB;
}

Transform frame_of(const std::vector<Transform>& X_GB, int mobility) {
  return mobility < 0 ? Transform() : X_GB[mobility];
}

void errors_from_frames(const ConstraintJacobianPlan& plan, const std::vector<Transform>& X_GB, const Vector& q,
                        Vector& perr) {
  perr.resize(plan.rows);
  int row = 0;
  for (size_t c = 0; c < plan.line_of.size(); ++c) {
    if (plan.line_of[c] < 0) {
      const auto& g = plan.gears[plan.gear_of[c]];
      perr[row++] = q[g.q_driven] - g.ratio * q[g.q_driver] - g.offset;
      continue;
    }
    const auto& l = plan.lines[plan.line_of[c]];
    const Vec3 p_S = frame_of(X_GB, l.follower_mobility) * l.point_F;
    const Vec3 p_PC = ~frame_of(X_GB, l.line_mobility) * p_S - l.point_L;  // as PointOnLineImpl's perr
    perr[row++] = dot(p_PC, Vec3(l.x_L));
    perr[row++] = dot(p_PC, Vec3(l.y_L));
  }
}

}  // namespace

void calc_constraint_jacobian(const FullModel::Impl& m, const State& s, Matrix& G) {
  const ConstraintJacobianPlan* plan = usable_plan(m, s);
  if (!plan) {
    m.matter.calcG(s, G);
    return;
  }
  // Per mobility: a pin's axis and pivot, a slider's direction, in Ground (M's z and origin: a
  // pin turns M about F's z with their origins together; a slider moves M along F's x = M's x).
  std::vector<Vec3> axis(plan->mobilities.size()), pivot(plan->mobilities.size());
  for (size_t k = 0; k < plan->mobilities.size(); ++k) {
    const auto& mob = plan->mobilities[k];
    const MobilizedBody& mb = m.matter.getMobilizedBody(mob.body);
    const Transform X_GM = mb.getBodyTransform(s) * mb.getOutboardFrame(s);
    axis[k] = mob.pin ? Vec3(X_GM.z()) : Vec3(X_GM.x());
    pivot[k] = X_GM.p();
  }
  fill_jacobian(*plan, axis, pivot, [&](const ConstraintJacobianPlan::LineRows& l) {
    return std::pair<Vec3, Rotation>(m.matter.getMobilizedBody(l.follower).findStationLocationInGround(s, l.point_F),
                                     m.matter.getMobilizedBody(l.line).getBodyRotation(s));
  }, G);
}

void calc_constraint_errors(const ConstraintJacobianPlan& plan, const Vector& q, Vector& perr) {
  errors_from_frames(plan, calc_body_frames(plan, q), q, perr);
}

void calc_constraint_errors_and_jacobian(const ConstraintJacobianPlan& plan, const Vector& q, Vector& perr,
                                         Matrix& G) {
  const std::vector<Transform> X_GB = calc_body_frames(plan, q);
  errors_from_frames(plan, X_GB, q, perr);
  std::vector<Vec3> axis(plan.mobilities.size()), pivot(plan.mobilities.size());
  for (size_t k = 0; k < plan.mobilities.size(); ++k) {
    const Transform X_GM = X_GB[k] * plan.mobilities[k].X_BM;
    axis[k] = plan.mobilities[k].pin ? Vec3(X_GM.z()) : Vec3(X_GM.x());
    pivot[k] = X_GM.p();
  }
  fill_jacobian(plan, axis, pivot, [&](const ConstraintJacobianPlan::LineRows& l) {
    return std::pair<Vec3, Rotation>(frame_of(X_GB, l.follower_mobility) * l.point_F,
                                     frame_of(X_GB, l.line_mobility).R());
  }, G);
}

}  // namespace rdyn::engine
