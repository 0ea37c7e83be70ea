#include "validate/harness/verdicts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rdyn::validate {

std::vector<Verdict> calc_verdicts(const std::vector<std::string>& quantities, const RunRecord* rec,
                                   double target) {
  std::vector<Verdict> out;
  for (const auto& q : quantities) {
    Verdict v;
    v.quantity = q;
    v.error = rec ? rec->error_of(q) : INFINITY;
    v.target = target;
    v.within_target = v.error <= target;
    out.push_back(v);
  }
  return out;
}

int pick_matched_full(const RunRecord& rec, const std::vector<RunRecord>& runs,
                      const std::vector<std::string>& quantities) {
  int best = -1;
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    if (r.model != "full" || !r.failure.empty() || !std::isfinite(r.wall_s)) continue;
    bool ok = true;
    for (const auto& q : quantities) ok &= r.error_of(q) <= rec.error_of(q);
    if (ok && (best < 0 || r.wall_s < runs[best].wall_s)) best = static_cast<int>(i);
  }
  return best;
}

int pick_most_accurate_full(const RunRecord& rec, const std::vector<RunRecord>& runs,
                            const std::vector<std::string>& quantities) {
  int best = -1;
  double best_ratio = INFINITY;
  for (size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    if (r.model != "full" || !r.failure.empty() || !std::isfinite(r.wall_s)) continue;
    double ratio = 0.0;
    for (const auto& q : quantities)
      ratio = std::max(ratio, r.error_of(q) / std::max(rec.error_of(q), std::numeric_limits<double>::min()));
    if (best < 0 || ratio < best_ratio) best = static_cast<int>(i), best_ratio = ratio;
  }
  return best;
}

std::vector<Baseline> calc_baselines(const RunRecord& rec, const RunRecord& reference,
                                     const std::vector<RunRecord>& runs, int compared_full, bool as_accurate) {
  std::vector<Baseline> out;
  auto add = [&](const std::string& what, const RunRecord& f) {
    if (!(rec.wall_s > 0 && std::isfinite(f.wall_s))) return false;
    out.push_back({what, f.label(), f.wall_s, f.wall_s / rec.wall_s});
    return true;
  };
  add("reference", reference);
  const RunRecord* cheapest = nullptr;
  for (const auto& r : runs)
    if (r.model == "full" && r.failure.empty() && (!cheapest || r.wall_s < cheapest->wall_s))
      cheapest = &r;
  if (compared_full >= 0) {
    // The cheapest run once: when it is the run compared with, that row says so.
    std::string what = as_accurate ? "full run at equal or better error" : "most accurate full run (less accurate)";
    if (cheapest == &runs[compared_full]) what += ", also the cheapest full run";
    if (add(what, runs[compared_full]) && cheapest == &runs[compared_full]) cheapest = nullptr;
  }
  if (cheapest) add("cheapest full run", *cheapest);
  return out;
}

ErrorBudget calc_error_budget(const RunRecord& run, const std::vector<RunRecord>& runs,
                              double reference_change, const std::string& q, double tol) {
  ErrorBudget b;
  b.reference = reference_change;
  b.total = run.error_of(q);
  b.table = NAN;
  b.integration = NAN;
  const SignalError* oi = run.output_interpolation.find(q);
  b.output_interpolation = oi ? oi->max_rel : NAN;
  for (const auto& r : runs)
    if (r.model == "reduced" && r.failure.empty() && std::abs(r.grid_deg - run.grid_deg) < 1e-9 &&
        r.interpolation == run.interpolation && r.energy_consistent == run.energy_consistent &&
        r.integrator == "rk8pd" && r.tolerance == tol) {
      b.table = r.error_of(q);
      b.table_run = r.label();
      b.integration = std::abs(b.total - b.table);
    }
  return b;
}

}  // namespace rdyn::validate
