// Assembly report and domain of the independent coordinate (`rdyn inspect`). The domain is the
// one walk every run uses (engine/independent_range.cpp), so inspect shows what extraction and
// both models' domain stop will use, not a second estimate of it.
#include "engine/inspect.hpp"

#include <cmath>

#include <fmt/format.h>

#include "engine/full_model_impl.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Pose of a scene body in ground at a state realized to Position (folded bodies turn about
// their ground joint: origin = parent point − R(offset + q)·child point).
AssembledBody body_pose(const FullModel::Impl& m, const State& s, int b) {
  const auto& bd = m.scene.bodies[b];
  AssembledBody out;
  out.name = bd.name;
  if (const auto& f = m.body_fold[b]) {
    const auto& jt = m.scene.joints[f->driven_joint];
    const double th = jt.offset_rad + m.joint_q(s, f->driven_joint);
    const double c = std::cos(th), sn = std::sin(th);
    out.angle_rad = th;
    out.x_m = jt.parent_point.x - (c * jt.child_point.x - sn * jt.child_point.y);
    out.y_m = jt.parent_point.y - (sn * jt.child_point.x + c * jt.child_point.y);
  } else {
    const Transform X = m.body_mobod[b].getBodyTransform(s);
    out.x_m = X.p()[0];
    out.y_m = X.p()[1];
    const Mat33 R = X.R().asMat33();
    out.angle_rad = std::atan2(R(1, 0), R(0, 0));
  }
  const double c = std::cos(out.angle_rad), sn = std::sin(out.angle_rad);
  out.com_x_m = out.x_m + c * bd.com_m.x - sn * bd.com_m.y;
  out.com_y_m = out.y_m + sn * bd.com_m.x + c * bd.com_m.y;
  return out;
}

}  // namespace

Inspection calc_assembly(const FullModel& model) {
  const auto& m = model.impl();
  const auto& sc = m.scene;
  FullWorkspace ws(model);  // assembles (and checks loops, degrees of freedom, branches)
  const State& s = ws.impl().state;
  m.system.realize(s, Stage::Position);
  Inspection out;
  out.length_scale_m = calc_length_scale(sc);
  for (size_t j = 0; j < sc.joints.size(); ++j) {
    const auto& jt = sc.joints[j];
    const bool rev = jt.type == models::JointType::Revolute;
    const double q = m.joint_q(s, static_cast<int>(j));
    if (!std::isfinite(q))
      throw models::NumericalError(fmt::format("{}: joint '{}' assembled at a non-finite coordinate", sc.source_file,
                                               jt.name));
    out.joints.push_back({jt.name, rev, q, jt.guess});
    if (static_cast<int>(j) == m.independent) continue;  // held at initial.q, not assembled
    if (rev) {
      const double d_deg = std::remainder(q - jt.guess, 2 * kPi) * 180 / kPi;
      if (std::abs(d_deg) > kFarFromGuess_deg)
        out.warnings.push_back(fmt::format(
            "joint '{}' assembled at {:.4g}°, {:.3g}° from its guess {:.4g}° (more than {:g}°): check that this is the "
            "branch you meant (a loop's `branch` names it)",
            jt.name, q * 180 / kPi, d_deg, jt.guess * 180 / kPi, kFarFromGuess_deg));
    } else if (std::abs(q - jt.guess) > kFarFromGuess_fraction * out.length_scale_m) {
      out.warnings.push_back(fmt::format(
          "joint '{}' assembled at {:.4g} m, {:.3g} m from its guess {:.4g} m (more than {:g} % of the mechanism's "
          "size {:.3g} m): check that this is the branch you meant (a loop's `branch` names it)",
          jt.name, q, q - jt.guess, jt.guess, 100 * kFarFromGuess_fraction, out.length_scale_m));
    }
  }
  for (size_t b = 0; b < sc.bodies.size(); ++b) out.bodies.push_back(body_pose(m, s, static_cast<int>(b)));
  for (const auto& l : sc.loops) {
    const Vec3 pa = m.mobod_of(l.body_a).findStationLocationInGround(s, Vec3(l.point_a.x, l.point_a.y, 0));
    const Vec3 pb = m.mobod_of(l.body_b).findStationLocationInGround(s, Vec3(l.point_b.x, l.point_b.y, 0));
    out.loops.push_back({l.name, (pa - pb).norm()});
  }
  calc_mobility_count(m, s, out.mobility.mobilities, out.mobility.rows, out.mobility.rank);
  return out;
}

Inspection calc_inspection(const FullModel& model) {
  Inspection out = calc_assembly(model);
  out.range = calc_independent_domain(model);
  // Runs still go (the full model runs unbounded), but no reduced table can be built.
  if (!out.range.unbounded_reason.empty()) out.warnings.push_back(out.range.unbounded_reason);
  return out;
}

}  // namespace rdyn::engine
