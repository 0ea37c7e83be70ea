#include "validate/harness/calibrated_run.hpp"

#include <algorithm>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibration_load.hpp"
#include "validate/harness/harness.hpp"

namespace rdyn::validate {

namespace {

// max |b − a| / max |a| over the rows both have.
double relative_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double peak = 0.0, diff = 0.0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    peak = std::max(peak, std::abs(a[i]));
    diff = std::max(diff, std::abs(b[i] - a[i]));
  }
  return peak > 0 ? diff / peak : NAN;
}

double mean_cadence(const models::TimeSeries& ts) {
  return ts.t.size() < 2 ? NAN : (ts.q.back() - ts.q.front()) / (2 * M_PI * (ts.t.back() - ts.t.front()));
}

}  // namespace

std::optional<CalibratedRun> calc_calibrated_run(const models::Scene& scene, const CalibrationOptions& opt,
                                                 const CalibrationResult& r, const reduced::Samples& samples10,
                                                 double dt_s) {
  if (!r.unconfirmed.empty() || samples10.q.empty() || !(opt.cadence_hz > 0) || !std::isfinite(r.steady_qdot))
    return std::nullopt;
  // The scene as `rdyn calibrate --write-scene` writes it: the load and resistance calibrated,
  // the initial state on the reduced steady cycle (validate/analysis/calibrated_scene.hpp).
  models::Scene sc = with_load(scene, select_load(scene, opt), std::abs(r.load_value), r.resistance_coefficient);
  sc.initial = models::Initial{r.steady_q, r.steady_qdot};
  CalibratedRun c;
  c.cadence_hz = opt.cadence_hz;
  const double duration = 2.0 / opt.cadence_hz;
  engine::ForwardOptions fo;
  fo.duration_s = duration;
  fo.output_interval_s = dt_s;
  fo.tolerance = 1e-10;
  c.full = engine::simulate_full(engine::FullModel(sc), fo);
  c.grid_deg = std::isfinite(r.grid_deg) ? r.grid_deg : opt.grid_deg;  // the calibration's (refined) grid
  const bool same_grid = std::abs(samples10.step * 180 / M_PI - c.grid_deg) < 1e-9 * c.grid_deg;
  const reduced::Samples table =
      same_grid ? samples10 : extract_from_full(extraction_scene(sc), c.grid_deg, reduced::Method::Kinetostatic).samples;
  const auto model = reduced::make_reduced_model(table, extraction_scene(sc), reduced::Interpolation::Fourier);
  reduced::ReducedOptions ro;
  ro.duration_s = duration;
  ro.output_interval_s = dt_s;
  ro.tolerance = 1e-10;
  ro.step_outputs = true;  // rows as accurate as the steps: the figure compares models, not output interpolation
  c.reduced = reduced::simulate_reduced(model, sc.initial.q, sc.initial.qdot, ro);
  c.qdot_error = relative_difference(c.full.qdot, c.reduced.qdot);
  if (!sc.outputs.constraint_forces.empty() && !c.full.forces.empty() && !c.reduced.forces.empty()) {
    c.force_name = sc.outputs.constraint_forces[0].name;
    c.force_error = relative_difference(c.full.forces[0], c.reduced.forces[0]);
  }
  c.mean_cadence_full_hz = mean_cadence(c.full);
  c.mean_cadence_reduced_hz = mean_cadence(c.reduced);
  return c;
}

}  // namespace rdyn::validate
