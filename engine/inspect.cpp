// Assembly report and range of the independent coordinate (`rdyn inspect`). The range walk is
// a bounded continuation of its own (engine/reduced_source.cpp keeps extraction's): steps of
// 2° (or 2 % of the length scale) with the secant predictor of engine/kinetostatic.cpp,
// quartered on each failed projection, so a dead point is bracketed to kDeadPointTolerance.
#include "engine/inspect.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "engine/full_model_impl.hpp"
#include "engine/kinetostatic.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Continuation moves one direction may take (successful and failed): a full turn in 2° steps is
// 180; each dead point costs ~log4(2°/1e-6 rad) ≈ 8 refinements per approach. 5000 bounds a
// prismatic walk of kSearchSpan length scales in 2 % steps (500) with room to spare.
constexpr int kMaxMoves = 5000;

double length_scale(const models::Scene& sc) {
  double L = 0.0;
  auto see = [&](models::Vec2 p) { L = std::max(L, std::hypot(p.x, p.y)); };
  for (const auto& [n, p] : sc.ground_points) see(p);
  for (const auto& b : sc.bodies) {
    see(b.com_m);
    for (const auto& [n, p] : b.points) see(p);
  }
  for (const auto& j : sc.joints) see(j.parent_point), see(j.child_point);
  for (const auto& l : sc.loops) see(l.point_a), see(l.point_b);
  return L > 0 ? L : 1.0;
}

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

// One direction of the range walk from the assembled configuration: the farthest q reached
// (at most `span` away) and whether a dead point stopped it.
std::pair<double, bool> walk(const FullModel& model, double dir, double span, double first_step) {
  FullWorkspace ws(model);
  const double q0 = model.scene().initial.q;
  double q = q0, step = first_step;
  for (int moves = 0; moves < kMaxMoves; ++moves) {
    if (std::abs(q - q0) >= span) return {q0 + dir * span, false};
    const double h = std::min(step, span - std::abs(q - q0));
    const Vector backup = ws.impl().state.getQ();
    try {
      move_configuration(model, ws, q + dir * h);
      q += dir * h;
    } catch (const EngineError&) {
      // The loops cannot close at q + h from here: a dead point lies within h.
      ws.impl().state.updQ() = backup;
      if (step < kDeadPointTolerance) return {q, true};
      step /= 4;
    }
  }
  throw models::NumericalError(fmt::format("{}: the range walk of '{}' did not finish in {} continuation moves",
                                           model.scene().source_file, model.scene().independent, kMaxMoves));
}

}  // namespace

Inspection calc_assembly(const FullModel& model) {
  const auto& m = model.impl();
  const auto& sc = m.scene;
  FullWorkspace ws(model);  // assembles (and checks loops, degrees of freedom, branches)
  const State& s = ws.impl().state;
  m.system.realize(s, Stage::Position);
  Inspection out;
  out.length_scale_m = length_scale(sc);
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
  const auto& sc = model.scene();
  const bool rev = sc.find_joint(sc.independent)->type == models::JointType::Revolute;
  const double q0 = sc.initial.q;
  const double span = rev ? 2 * kPi : kSearchSpan * out.length_scale_m;
  const double first = rev ? 2 * kPi / 180 : 0.02 * out.length_scale_m;
  const auto [hi, hi_dead] = walk(model, +1.0, span, first);
  if (rev && !hi_dead) {
    out.range = {true, q0 - kPi, q0 + kPi, false, false};
    return out;
  }
  const auto [lo, lo_dead] = walk(model, -1.0, span, first);
  out.range = {false, lo, hi, lo_dead, hi_dead};
  const double unit = rev ? 180 / kPi : 1.0;
  const char* u = rev ? "°" : " m";
  for (const auto& [at, dead, which] : {std::tuple{lo, lo_dead, "lower"}, std::tuple{hi, hi_dead, "upper"}})
    if (dead && std::abs(at - q0) < 0.02 * (hi - lo))
      out.warnings.push_back(fmt::format("the initial {} = {:.6g}{} is within 2 % of the range of its {} dead point "
                                         "{:.6g}{}: the motion leaves the mechanism's range almost at once",
                                         sc.independent, q0 * unit, u, which, at * unit, u));
  if (!rev && !(lo_dead && hi_dead))
    out.warnings.push_back(fmt::format("no dead point of '{}' within {:g} × the mechanism's size ({:.3g} m) of its "
                                       "initial value on {}: the range reported is the search's",
                                       sc.independent, kSearchSpan, out.length_scale_m,
                                       lo_dead ? "the upper side" : hi_dead ? "the lower side" : "either side"));
  return out;
}

}  // namespace rdyn::engine
