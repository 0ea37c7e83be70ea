#include "validate/harness/convergence.hpp"

#include <algorithm>
#include <cmath>

namespace rdyn::validate {

double calc_observed_order(const std::vector<std::pair<double, double>>& pts, double floor) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& [g, e] : pts) {
    if (!(e > floor) || !std::isfinite(e) || !(g > 0)) continue;
    const double x = std::log(g), y = std::log(e);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  const double den = n * sxx - sx * sx;
  if (n < 2 || !(den > 0)) return NAN;
  return (n * sxy - sx * sy) / den;
}

std::vector<ConvergenceSeries> calc_convergence(const std::vector<RunRecord>& runs,
                                                const std::string& q, double tolerance,
                                                double floor) {
  std::vector<ConvergenceSeries> out;
  for (const auto& r : runs) {
    if (r.model != "reduced" || r.energy_consistent || r.integrator != "rk8pd" ||
        r.tolerance != tolerance)
      continue;
    if (!r.failure.empty() || !std::isfinite(r.error_of(q))) continue;
    auto it = std::find_if(out.begin(), out.end(),
                           [&](const auto& s) { return s.interpolation == r.interpolation; });
    if (it == out.end()) it = out.insert(out.end(), ConvergenceSeries{r.interpolation, {}, NAN});
    it->points.push_back({r.grid_deg, r.error_of(q)});
  }
  for (auto& s : out) {
    std::sort(s.points.begin(), s.points.end(), [](auto a, auto b) { return a.first > b.first; });
    s.order = calc_observed_order(s.points, floor);
  }
  return out;
}

}  // namespace rdyn::validate
