#include "validate/harness/thresholds.hpp"

#include <cmath>

namespace rdyn::validate {

std::vector<models::Threshold> thresholds_of(const models::Scene& scene) {
  if (!scene.validation.thresholds.empty()) return scene.validation.thresholds;
  std::vector<models::Threshold> th{{"qdot", kDefaultThresholdGrid_deg, "", kDefaultThresholdMaxError}};
  for (const auto& f : scene.outputs.constraint_forces)
    th.push_back({f.name, kDefaultThresholdGrid_deg, "", kDefaultThresholdMaxError});
  return th;
}

ThresholdResult judge_threshold_on(const models::Threshold& th, const RunRecord& r) {
  ThresholdResult t{th, r.error_of(th.quantity), false, r.label()};
  // An error relative to a peak of zero (a mechanism at rest, a force that never acts) is no
  // error at all: the threshold cannot be met (issue #9, "never exit 0 on nothing").
  const SignalError* s = r.errors.find(th.quantity);
  if (s && !(s->peak > 0)) {
    t.error = NAN;
    t.run += " (the reference's peak of " + th.quantity + " is 0: no relative error exists)";
  }
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
