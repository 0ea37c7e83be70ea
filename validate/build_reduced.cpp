#include "validate/build_reduced.hpp"

#include <chrono>

#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"
#include "engine/reduced_source.hpp"

namespace rdyn::validate {

Extraction extract_from_full(const models::Scene& scene, double grid_deg, reduced::Method method) {
  const auto start = std::chrono::steady_clock::now();
  engine::FullModel model(scene);
  engine::FullKinetostaticSource source(model);
  reduced::ExtractOptions opt;
  opt.step_rad = grid_deg * 3.14159265358979323846 / 180.0;
  opt.method = method;
  Extraction e;
  // A revolute that turns fully gives a periodic table; otherwise the declared range or the
  // one between the dead points (engine/independent_range.hpp).
  const auto domain = engine::calc_independent_domain(model);
  if (!domain.periodic) {
    opt.range = reduced::ExtractRange{domain.min, domain.max, domain.min_edge, domain.max_edge};
    e.range = opt.range;
    e.dead_min = domain.dead_min;
    e.dead_max = domain.dead_max;
  }
  e.samples = reduced::extract_samples(source, scene, opt);
  e.extraction_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  e.calls = source.calls();
  return e;
}

}  // namespace rdyn::validate
