#include "validate/harness/grid_check.hpp"

#include "validate/harness/compare.hpp"

namespace rdyn::validate {

nlohmann::json grid_check_json(const GridCheck& check) {
  auto positive_or_null = [](double x) { return x > 0 ? nlohmann::json(x) : nlohmann::json(); };
  return {{"grid_deg", check.grid_deg},
          {"finer_grid_deg", positive_or_null(check.finer_grid_deg)},
          {"coarser_grid_deg", positive_or_null(check.coarser_grid_deg)},
          {"column", check.column},
          {"change", std::isfinite(check.change) ? nlohmann::json(check.change) : nlohmann::json()},
          {"max_change", kGridCheckMaxChange},
          {"verified", check.verified},
          {"not_compared", check.not_compared}};
}

std::pair<std::string, double> calc_run_change(const models::TimeSeries& finer, const models::TimeSeries& coarser) {
  std::pair<std::string, double> worst{"", 0.0};
  const Comparison c = compare_series(finer, coarser, 0.0);
  for (size_t i = 0; i < c.signals.size(); ++i) {
    const auto& s = c.signals[i];
    // The mean speed is a summary of qdot, which is compared row by row.
    if (s.name == "mean_qdot") continue;
    // Named as the CSV names its column: the constraint forces (signals 1 … nf) F_<name>.
    const bool force = i >= 1 && i <= finer.force_names.size();
    if (s.max_rel > worst.second || std::isnan(s.max_rel)) worst = {(force ? "F_" : "") + s.name, s.max_rel};
  }
  return worst;
}

}  // namespace rdyn::validate
