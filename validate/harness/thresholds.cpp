#include "validate/harness/thresholds.hpp"

#include <cmath>

namespace rdyn::validate {

std::vector<models::Threshold> thresholds_of(const models::Scene& scene, const std::vector<std::string>& judged,
                                             double default_grid_deg) {
  if (!scene.validation.thresholds.empty()) return scene.validation.thresholds;
  std::vector<models::Threshold> th;
  for (const auto& q : judged)
    if (q != "mean_qdot") th.push_back({q, default_grid_deg, "", kDefaultThresholdMaxError});
  return th;
}

ThresholdResult judge_threshold_on(const models::Threshold& th, const RunRecord& r) {
  ThresholdResult t{th, r.error_of(th.quantity), false, r.label()};
  // An error relative to a peak of zero (a mechanism at rest, a force that never acts) is no
  // error at all: the threshold cannot be met (issue #9, "never exit 0 on nothing").
  const SignalError* s = r.errors.find(th.quantity);
  if (s && !(s->peak > 0) && r.failure.empty()) {  // a stopped run records no peaks
    t.error = NAN;
    t.run += " (the reference's peak of " + th.quantity + " is 0: no relative error exists)";
  }
  if (!r.failure.empty()) t.run += " (stopped: " + r.failure + ")";  // why the error is +∞
  t.pass = t.error <= th.max_error;  // false for NaN and +∞ (a stopped run)
  return t;
}

std::optional<ThresholdResult> judge_threshold(const models::Threshold& th,
                                               const std::vector<RunRecord>& runs,
                                               double tolerance) {
  const std::string interp = th.interpolation.empty() ? kDefaultInterpolation : th.interpolation;
  for (const auto& r : runs)
    if (r.model == "reduced" && std::abs(r.grid_deg - th.grid_deg) < 1e-9 &&
        r.interpolation == interp && !r.energy_consistent && r.integrator == "rk8pd" &&
        r.tolerance == tolerance)
      return judge_threshold_on(th, r);
  return std::nullopt;
}

}  // namespace rdyn::validate
