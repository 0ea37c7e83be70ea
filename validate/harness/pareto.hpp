// Accuracy against cost over the run records: the Pareto front, the matched-error speedup and
// the recommended reduced setting. Costs are whole-run wall times; every run of one
// validation simulates the same duration, so their ratios need no per-second scaling.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "validate/harness/run_record.hpp"

namespace rdyn::validate {

// Marks r.pareto on every run no run of the same model beats in both cost and the error
// of `quantity` (ties in both keep both). Stopped runs (infinite cost) are never on it.
void mark_pareto(std::vector<RunRecord>& runs, const std::string& quantity);

struct MatchedSpeedup {
  int full = -1, reduced = -1;    // indices into the runs
  std::optional<double> speedup;  // full wall / reduced wall
};

// The cheapest `baseline` run ("full", or a peer engine's model name) within `target` on
// `quantity`, then the cheapest reduced run at equal or better error; the speedup is their cost
// ratio.
MatchedSpeedup calc_matched_speedup(const std::vector<RunRecord>& runs, const std::string& quantity,
                                    double target, const std::string& baseline = "full");

// The cheapest completed reduced run within `target` on every one of `quantities`; −1 if none.
int pick_recommended(const std::vector<RunRecord>& runs, const std::vector<std::string>& quantities,
                     double target);

}  // namespace rdyn::validate
