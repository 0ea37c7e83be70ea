#include "engine/independent_range.hpp"
#include "engine/singular_passage.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "engine/full_model_impl.hpp"
#include "engine/kinetostatic.hpp"

namespace rdyn::engine {

using namespace SimTK;

namespace {

constexpr double kPi = 3.14159265358979323846;
// Bisection stops when the bracket is this narrow [rad or m] (the dead point is then known to
// ~1e-11, far below any grid step; the projection itself holds the loops to 1e-12 m).
constexpr double kBisectionWidth = 1e-11;
// Continuation moves one walk may take (each a projection): a revolute turn at the finest
// move (0.2°) is 1800; a prismatic walk of 40 sizes at the finest (size/1000) is 40 000.
constexpr long kMaxMoves = 50000;

// Moves the workspace to q from its current (good) configuration; on failure restores it.
// Tries the secant-predicted projection (1e-12), then the kinetostatic projection, which
// accepts 1e-9 at a singular configuration (a parallelogram's aligned position is passable,
// a dead point is not: beyond it the loops cannot close at any tolerance).
bool try_reach(const FullModel& model, FullWorkspace& ws, double q) {
  const Vector good = ws.impl().state.getQ();
  try {
    move_configuration(model, ws, q);
    return true;
  } catch (const EngineError&) {
  } catch (const models::NumericalError&) {
  }
  ws.impl().state.updQ() = good;
  try {
    calc_kinetostatic(model, ws, q, 0.0, 0.0, Loads::Off);
    return true;
  } catch (const EngineError&) {
  } catch (const models::NumericalError&) {
  }
  ws.impl().state.updQ() = good;
  return false;
}

struct Walk {
  bool full_turn = false;
  std::optional<double> dead;  // last reachable q before the dead point
};

// Walks from the initial configuration in direction dir (±1) until a dead point (bisected),
// a full turn (revolute) or `limit` of travel.
Walk walk(const FullModel& model, double dir, double h0, double limit, bool revolute, long& moves) {
  FullWorkspace ws(model);
  const double q0 = model.scene().initial.q;
  double q = q0, h = h0;
  Walk out;
  while (std::abs(q - q0) < limit) {
    if (++moves > kMaxMoves)
      // A numerical failure (exit 1), not bad input: the scene was valid, the walk did not end.
      throw models::NumericalError(fmt::format("{}: the search for the dead points of '{}' took more than {} moves",
                                               model.scene().source_file, model.scene().independent, kMaxMoves));
    const double q_try = q + dir * std::min(h, limit - std::abs(q - q0) + 1e-12);
    if (try_reach(model, ws, q_try)) {
      q = q_try;
      continue;
    }
    if (h > h0 / 50 * 1.0000001) {  // finer moves before calling it a dead point
      h /= 5;
      continue;
    }
    // Dead point between q (reachable) and q_try (not): bisect.
    double a = q, b = q_try;
    for (int it = 0; it < 200 && std::abs(b - a) > kBisectionWidth; ++it) {
      const double mid = 0.5 * (a + b);
      if (try_reach(model, ws, mid)) a = mid;
      else b = mid;
    }
    out.dead = 0.5 * (a + b);
    return out;
  }
  out.full_turn = revolute;
  return out;
}

}  // namespace

double calc_length_scale(const models::Scene& s) {
  double L = 1e-3;
  auto add = [&](models::Vec2 p) { L = std::max(L, std::hypot(p.x, p.y)); };
  for (const auto& [n, p] : s.ground_points) add(p);
  for (const auto& b : s.bodies) {
    add(b.com_m);
    for (const auto& [n, p] : b.points) add(p);
  }
  for (const auto& j : s.joints) add(j.parent_point), add(j.child_point);
  for (const auto& l : s.loops) add(l.point_a), add(l.point_b);
  for (const auto& sp : s.springs) add(sp.point_a), add(sp.point_b);
  for (const auto& f : s.point_forces) add(f.point_a), add(f.point_b);
  // A prismatic joint's own travel is part of the size: a lone slider whose points all sit at
  // its origin would otherwise get 1 mm, and continuation over a 1 m stroke would need 2·10⁴
  // moves (over the approach budget).
  for (const auto& j : s.joints)
    if (j.type == models::JointType::Prismatic) L = std::max(L, std::abs(j.guess));
  if (const auto* jt = s.find_joint(s.independent); jt && jt->type == models::JointType::Prismatic) {
    L = std::max(L, std::abs(s.initial.q));
    if (s.independent_range)
      L = std::max({L, std::abs(s.independent_range->min), std::abs(s.independent_range->max)});
  }
  return L;
}

std::string format_coordinate(double q, bool revolute) {
  return revolute ? fmt::format("q = {:.9g}°", q * 180 / kPi) : fmt::format("q = {:.9g} m", q);
}

double calc_dead_point_margin(const IndependentDomain& d) {
  return d.dead_min && d.dead_max ? kDeadPointMargin * (*d.dead_max - *d.dead_min) : 0.0;
}

std::string describe_domain(const IndependentDomain& d, const std::string& joint) {
  const double k = d.revolute ? 180 / kPi : 1.0;
  const std::string unit = d.revolute ? "°" : " m";
  if (d.periodic) return fmt::format("full turn: '{}' turns fully (the walk met no dead point in 360°)", joint);
  if (!d.unbounded_reason.empty()) return d.unbounded_reason;
  if (!d.dead_min || !d.dead_max)
    return fmt::format("declared by the scene: independent_range [{:.9g}, {:.9g}]{}", d.min * k, d.max * k, unit);
  return fmt::format(
      "dead points found at {:.9g}{} and {:.9g}{} (the loops cannot close beyond them; located by bisection); "
      "the range stops {:.6g}{} ({:g} % of their distance) short of each: [{:.9g}, {:.9g}]{}",
      *d.dead_min * k, unit, *d.dead_max * k, unit, calc_dead_point_margin(d) * k, unit, 100 * kDeadPointMargin,
      d.min * k, d.max * k, unit);
}

namespace {

IndependentDomain calc_domain_edges(const FullModel& model) {
  const auto& sc = model.scene();
  const auto* jt = sc.find_joint(sc.independent);
  if (!jt) throw EngineError(sc.source_file + ": unknown independent joint '" + sc.independent + "'");
  IndependentDomain d;
  d.revolute = jt->type == models::JointType::Revolute;
  const double h0 = d.revolute ? 10.0 * kPi / 180 : calc_length_scale(sc) / 20;
  long moves = 0;
  const std::string unit = d.revolute ? "°" : " m";
  const double k = d.revolute ? 180 / kPi : 1.0;
  if (sc.independent_range) {
    d.min = sc.independent_range->min;
    d.max = sc.independent_range->max;
    d.min_edge = d.max_edge = "declared limit";
    // The declared range must be reachable: walk to both ends (a dead point inside is refused,
    // as extraction would refuse it).
    const double q0 = sc.initial.q;
    for (const auto& [dir, span] : {std::pair{+1.0, d.max - q0}, std::pair{-1.0, q0 - d.min}}) {
      if (!(span > 0)) continue;
      const Walk w = walk(model, dir, std::min(h0, span), span, false, moves);
      if (w.dead)
        throw EngineError(fmt::format(
            "{}: independent_range [{:.9g}, {:.9g}]{} of '{}' crosses a dead point at {:.9g}{} (the loops cannot "
            "close beyond it): declare a range inside the dead points, or leave it out and rdyn finds them",
            models::where(sc, sc.line_of("independent_range_deg") > 0 ? "independent_range_deg" : "independent_range"),
            d.min * k, d.max * k, unit, sc.independent, *w.dead * k, unit));
    }
    return d;
  }
  const double limit = d.revolute ? 2 * kPi : 40 * calc_length_scale(sc);
  const Walk up = walk(model, +1.0, h0, limit, d.revolute, moves);
  if (up.full_turn) {
    d.periodic = true;
    return d;
  }
  const Walk down = walk(model, -1.0, h0, limit, d.revolute, moves);
  if (!up.dead || !down.dead) {
    // No range can be found: unbounded for the full model (which can run), refused by extraction.
    d.min = -INFINITY;
    d.max = INFINITY;
    d.unbounded_reason = fmt::format(
        "{}: the independent coordinate '{}' meets {} within {:g}{} of its initial value: rdyn cannot find its "
        "range; declare independent_range: [min, max] in the scene",
        sc.source_file, sc.independent, up.dead || down.dead ? "only one dead point" : "no dead point", limit * k,
        unit);
    return d;
  }
  d.dead_min = *down.dead;
  d.dead_max = *up.dead;
  const double margin = calc_dead_point_margin(d);
  d.min = *d.dead_min + margin;
  d.max = *d.dead_max - margin;
  d.min_edge = d.max_edge = "dead point";
  if (!(sc.initial.q > d.min && sc.initial.q < d.max))
    throw EngineError(fmt::format(
        "{}: the initial {} lies within {:g} % of a dead point of '{}' (dead points at {:.9g}{} and {:.9g}{}; the "
        "range rdyn uses stops {:g} % of their distance short of each): start further inside, or declare "
        "independent_range",
        models::where(sc, "initial"), format_coordinate(sc.initial.q, d.revolute), 100 * kDeadPointMargin, sc.independent,
        *d.dead_min * k, unit, *d.dead_max * k, unit, 100 * kDeadPointMargin));
  return d;
}

}  // namespace

IndependentDomain calc_independent_domain_edges(const FullModel& model) { return calc_domain_edges(model); }

IndependentDomain calc_independent_domain(const FullModel& model) {
  IndependentDomain d = calc_domain_edges(model);
  d.singular = calc_singular_points(model, d);
  return d;
}

}  // namespace rdyn::engine
