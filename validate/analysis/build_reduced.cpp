#include "validate/analysis/build_reduced.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"
#include "engine/reduced_source.hpp"
#include "models/gear_fold.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/table_resolution.hpp"

namespace rdyn::validate {

namespace {
using clock = std::chrono::steady_clock;
double ms(clock::time_point a, clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }
}  // namespace

Extraction extract_from_full(const models::Scene& scene, double grid_deg, reduced::Method method,
                             bool require_closed_turn) {
  const auto start = clock::now();
  const engine::FullModel model(scene);
  const double build_ms = ms(start, clock::now());
  Extraction e = extract_from_full(model, grid_deg, method, require_closed_turn);
  e.stages.system_build_ms = build_ms;
  e.extraction_ms += build_ms;
  return e;
}

Extraction extract_from_full(const engine::FullModel& model, double grid_deg, reduced::Method method,
                             bool require_closed_turn) {
  const models::Scene& scene = model.scene();
  const auto start = clock::now();
  reduced::ExtractOptions opt;
  opt.step_rad = grid_deg * 3.14159265358979323846 / 180.0;
  opt.method = method;
  opt.require_closed_turn = require_closed_turn;
  Extraction e;
  auto finish = [&](const engine::FullKinetostaticSource& source) {
    const auto end = clock::now();
    e.extraction_ms = ms(start, end);
    e.stages.kinetostatics_ms = e.extraction_ms - e.stages.system_build_ms - e.stages.assembly_ms;
    e.calls = source.calls();
    return e;
  };
  // A revolute without a declared range is first swept as a full turn (the periodic table,
  // at no extra cost); a dead point on the way means it has a range instead.
  const auto& ind = *scene.find_joint(scene.independent);
  std::optional<engine::IndependentDomain> domain;
  if (ind.type == models::JointType::Revolute && !scene.independent_range) {
    try {
      const auto t = clock::now();
      engine::FullKinetostaticSource source(model);
      e.stages.assembly_ms = ms(t, clock::now());
      e.samples = reduced::extract_samples(source, scene, opt);
      // Poorly conditioned somewhere: rank loss may lie between grid points, where a constraint
      // force may have a pole no grid sample shows (an isosceles crank on a 7.2° grid: the rod
      // force swung ±125 N for the full model's 1.7 N). Scan for it, and where some lies off the
      // grid, sweep again checking each (reduced::ExtractOptions::singular_hints).
      if (e.samples.min_conditioning < reduced::kScanBelowConditioning) {
        const auto scanned = engine::calc_independent_domain(model);
        for (const auto& sp : scanned.singular) {
          double off = INFINITY;  // distance to the nearest grid point, over the turn
          for (double q : e.samples.q) off = std::min(off, std::abs(std::remainder(sp.q - q, 2 * M_PI)));
          if (off > 1e-9) opt.singular_hints.push_back(sp.q);
        }
        if (!opt.singular_hints.empty()) {
          const long first_calls = source.calls();
          engine::FullKinetostaticSource again(model);
          e.samples = reduced::extract_samples(again, scene, opt);
          Extraction out = finish(again);
          out.calls += first_calls;
          return out;
        }
      }
      return finish(source);
    } catch (const engine::EngineError&) {
      domain = engine::calc_independent_domain(model);
      if (domain->periodic) throw;  // not a dead point: the sweep's own failure
    } catch (const reduced::SweepNotClosed&) {
      // The sweep changed branch on the way round (over a narrow blocked range): the dead points
      // bound a range, when the walk finds them; otherwise the sweep's message stands.
      domain = engine::calc_independent_domain(model);
      if (domain->periodic) throw;
    }
  }
  // The declared range or the one between the dead points (engine/independent_range.hpp).
  if (!domain) domain = engine::calc_independent_domain(model);
  if (!domain->unbounded_reason.empty()) throw engine::EngineError(domain->unbounded_reason);
  opt.range = reduced::ExtractRange{domain->min, domain->max, domain->min_edge, domain->max_edge};
  for (const auto& sp : domain->singular) opt.singular_hints.push_back(sp.q);  // the walk's scan
  e.dead_min = domain->dead_min;
  e.dead_max = domain->dead_max;
  const auto t = clock::now();
  engine::FullKinetostaticSource source(model, /*wrap_turns=*/false);
  e.stages.assembly_ms = ms(t, clock::now());  // a failed full-turn attempt counts as kinetostatics
  try {
    e.samples = reduced::extract_samples(source, scene, opt);
  } catch (const reduced::PointForceMeeting& meet) {
    // A range whose point force's points meet inside it ends there, on the side of the start: a
    // cylinder-driven lift whose cable's points meet at a stroke the motion never reaches was
    // refused while the full model ran (it stops only when a run gets there, as the table's edge
    // now stops the reduced one). A margin of 1e-3 of the range keeps the points apart by more than the
    // 1e-6 m a line needs for a direction (models::limits::kMinPointForceLength_m).
    const double q0 = scene.initial.q, margin = 1e-3 * (opt.range->max - opt.range->min);
    if (meet.q - margin > q0 && meet.q - margin > opt.range->min + margin)
      opt.range->max = meet.q - margin, opt.range->max_edge = reduced::kPointForceMeetingEdge;
    else if (meet.q + margin < q0 && meet.q + margin < opt.range->max - margin)
      opt.range->min = meet.q + margin, opt.range->min_edge = reduced::kPointForceMeetingEdge;
    else
      throw;
    std::fprintf(stderr, "rdyn: point force '%s': its points meet at q = %.6g inside the range: the table ends there\n",
                 meet.load.c_str(), meet.q);
    e.samples = reduced::extract_samples(source, scene, opt);
  }
  e.range = opt.range;
  return finish(source);
}

std::pair<std::string, double> calc_resolution_miss(const reduced::Samples& samples) {
  std::pair<std::string, double> worst{"m1", NAN};
  const int c_m1 = samples.column("m1");
  double m1_peak = 0.0;
  if (c_m1 >= 0)
    for (double x : samples.columns[c_m1]) m1_peak = std::max(m1_peak, std::abs(x));
  for (const char* name : {"m1", "Q_cons"}) {
    const int c = samples.column(name);
    if (c < 0) continue;
    // A Q_cons that is rounding (no gravity, no spring: ~1e-17 N·m) has no shape to resolve: it
    // below 1e-9 of m1's peak (as N·m at 1 rad/s²) is left out. A mechanism at rest without loads
    // was halved down to 0.3125° chasing a "miss of 82 %" of its noise.
    if (c != c_m1) {
      double peak = 0.0;
      for (double x : samples.columns[c]) peak = std::max(peak, std::abs(x));
      if (peak < 1e-9 * m1_peak) continue;
    }
    const double miss = reduced::calc_half_grid_miss(samples.columns[c]);
    if (std::isnan(worst.second) || miss > worst.second) worst = {name, miss};
  }
  return worst;
}

std::pair<std::string, double> calc_line_resolution_miss(const reduced::Samples& samples, const models::Scene& scene) {
  std::pair<std::string, double> worst{"", 0.0};
  if (!samples.periodic || samples.q.size() < 8 || samples.q.size() % 2 != 0) return worst;
  // Every constraint line's force along the turn at the scene's starting speed, with q̈ from the
  // model there: at the grid points any interpolation gives the samples, so the cheapest one
  // evaluates them. Its own peak is the scale (as validate judges it), floored at 1e-9 of the
  // largest line's (a reaction zero but for rounding, compare_series's rule).
  reduced::ReducedModel m;
  try {
    m = reduced::make_reduced_model(samples, scene, reduced::Interpolation::Linear);
  } catch (const reduced::TableError&) {
    return worst;  // not a model on this grid: m1 and Q_cons decide
  }
  const size_t nf = m.force_names.size(), n = samples.q.size();
  if (nf == 0) return worst;
  const double omega = scene.initial.qdot;
  reduced::ReducedWorkspace ws(m);
  ws.q = samples.q[0], ws.qdot = omega;
  reduced::init_gates(m, ws);
  std::vector<std::vector<double>> f(nf, std::vector<double>(n));
  std::vector<double> row(nf);
  for (size_t i = 0; i < n; ++i) {
    double qddot = 0.0, power_nc = 0.0;
    reduced::calc_sample(m, ws, samples.q[i], omega, qddot, power_nc, row.data());
    for (size_t k = 0; k < nf; ++k) f[k][i] = row[k];
  }
  double scale = 0.0;
  for (const auto& c : f)
    for (double x : c) scale = std::max(scale, std::abs(x));
  for (size_t k = 0; k < nf; ++k) {
    double peak = 0.0;
    for (double x : f[k]) peak = std::max(peak, std::abs(x));
    const double miss = reduced::calc_half_grid_miss(f[k]) * peak / std::max(peak, 1e-9 * scale);
    if (miss > worst.second) worst = {"the force of line " + m.force_names[k], miss};
  }
  return worst;
}

namespace {

// extract_resolving's halving, over any way of extracting at a grid (a scene's new system, or
// one already built). `say`: each step on standard error.
template <class Extract>
Extraction resolve(const models::Scene& scene, const Extract& extract, double grid_deg, bool grid_given, bool say,
                   double& grid_deg_used) {
  double grid = grid_deg;
  // A default grid whose full-turn sweep did not close (it changed assembly between two grid
  // points: a 1:20 gear turns its joint 200° per 10° step) is halved too: a given one is the
  // user's, and its refusal stands. So is the refusal of gears that do not bring every joint back
  // after one turn (a 1:2 pair driven from its fast side): no grid closes that turn, and halving
  // five times took 1.4 s before the same message.
  std::string gears_why;
  const bool gears_repeat = models::calc_turns_to_repeat(scene, gears_why) == 1;
  Extraction e;
  for (;;) {
    try {
      e = extract(grid);
      break;
    } catch (const reduced::SweepNotClosed&) {
      if (grid_given || !gears_repeat || grid / 2 < kMinAutoGrid_deg - 1e-9) throw;
      if (say) std::fprintf(stderr, "rdyn: the %g° sweep did not close its turn: extracting at %g°\n", grid, grid / 2);
      grid /= 2;
    }
  }
  while (!grid_given && e.samples.periodic && grid / 2 >= kMinAutoGrid_deg - 1e-9) {
    auto [column, miss] = calc_resolution_miss(e.samples);
    if (!(miss > kAutoRefineMiss)) {
      std::tie(column, miss) = calc_line_resolution_miss(e.samples, scene);
      if (!(miss > kAutoRefineLineMiss)) break;
    }
    if (say)
      std::fprintf(stderr,
                   "rdyn: the %g° table does not resolve this mechanism (%s from every other grid point misses the "
                   "others by %.2g %% of its peak): extracting at %g°\n",
                   grid, column.c_str(), 100 * miss, grid / 2);
    grid /= 2;
    e = extract(grid);
  }
  grid_deg_used = grid;
  return e;
}

}  // namespace

Extraction extract_resolving(const models::Scene& scene, double grid_deg, bool grid_given, reduced::Method method,
                             double& grid_deg_used) {
  return resolve(scene, [&](double g) { return extract_from_full(scene, g, method); }, grid_deg, grid_given, true,
                 grid_deg_used);
}

Extraction extract_resolving(const engine::FullModel& model, double grid_deg, bool grid_given, reduced::Method method,
                             bool say, double& grid_deg_used) {
  return resolve(model.scene(), [&](double g) { return extract_from_full(model, g, method); }, grid_deg, grid_given,
                 say, grid_deg_used);
}

}  // namespace rdyn::validate
