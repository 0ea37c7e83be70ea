#include "validate/harness/pareto.hpp"

#include <cmath>

namespace rdyn::validate {

void mark_pareto(std::vector<RunRecord>& runs, const std::string& q) {
  for (auto& r : runs) {
    r.pareto = r.failure.empty() && std::isfinite(r.wall_s);
    if (!r.pareto) continue;
    const double er = r.error_of(q);
    for (const auto& o : runs) {
      if (&o == &r || o.model != r.model || !o.failure.empty()) continue;
      const double eo = o.error_of(q);
      if (o.wall_s <= r.wall_s && eo <= er && (o.wall_s < r.wall_s || eo < er)) {
        r.pareto = false;
        break;
      }
    }
  }
}

MatchedSpeedup calc_matched_speedup(const std::vector<RunRecord>& runs, const std::string& q,
                                    double target, const std::string& baseline) {
  MatchedSpeedup m;
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    if (r.model != baseline || !r.failure.empty() || !(r.error_of(q) <= target)) continue;
    if (m.full < 0 || r.wall_s < runs[m.full].wall_s) m.full = static_cast<int>(i);
  }
  if (m.full < 0) return m;
  const double e_full = runs[m.full].error_of(q);
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    if (r.model != "reduced" || !r.failure.empty() || !(r.error_of(q) <= e_full)) continue;
    if (m.reduced < 0 || r.wall_s < runs[m.reduced].wall_s) m.reduced = static_cast<int>(i);
  }
  if (m.reduced >= 0 && runs[m.reduced].wall_s > 0)
    m.speedup = runs[m.full].wall_s / runs[m.reduced].wall_s;
  return m;
}

int pick_recommended(const std::vector<RunRecord>& runs, const std::vector<std::string>& quantities,
                     double target) {
  int best = -1;
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    if (r.model != "reduced" || !r.failure.empty()) continue;
    bool ok = true;
    for (const auto& q : quantities) ok &= r.error_of(q) <= target;
    if (ok && (best < 0 || r.wall_s < runs[best].wall_s)) best = static_cast<int>(i);
  }
  return best;
}

}  // namespace rdyn::validate
