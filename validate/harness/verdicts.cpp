#include "validate/harness/verdicts.hpp"

#include <cmath>
#include <limits>

namespace rdyn::validate {

std::vector<Verdict> calc_verdicts(const std::vector<std::string>& quantities, const RunRecord* rec,
                                   const std::vector<ThresholdResult>& thresholds, double target) {
  std::vector<Verdict> out;
  for (const auto& q : quantities) {
    Verdict v;
    v.quantity = q;
    v.error = rec ? rec->error_of(q) : INFINITY;
    const ThresholdResult* th = nullptr;
    for (const auto& t : thresholds)
      if (t.threshold.quantity == q && (!th || t.threshold.max_error < th->threshold.max_error))
        th = &t;
    if (th) {
      v.limit = th->threshold.max_error;
      v.judged_on = th->run;
      v.judged_error = th->error;
      v.pass = th->pass;
      v.decides = true;
    } else {
      v.limit = target;
      v.judged_on = rec ? rec->label() : "no reduced run within the target";
      v.judged_error = v.error;
      v.pass = v.error <= target;
    }
    out.push_back(v);
  }
  return out;
}

std::vector<Baseline> calc_baselines(const RunRecord& rec, const RunRecord& reference,
                                     const std::vector<RunRecord>& runs, int matched_full) {
  std::vector<Baseline> out;
  auto add = [&](const char* what, const RunRecord& f) {
    if (rec.wall_s > 0 && std::isfinite(f.wall_s))
      out.push_back({what, f.label(), f.wall_s, f.wall_s / rec.wall_s});
  };
  add("reference", reference);
  if (matched_full >= 0) add("matched-error full run", runs[matched_full]);
  const RunRecord* cheapest = nullptr;
  for (const auto& r : runs)
    if (r.model == "full" && r.failure.empty() && (!cheapest || r.wall_s < cheapest->wall_s))
      cheapest = &r;
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
