// Acceptance thresholds of a scene, judged on the run records.
#pragma once

#include <optional>
#include <vector>

#include "models/scene.hpp"
#include "validate/harness/run_record.hpp"

namespace rdyn::validate {

// The interpolation a threshold without one is judged at (the tool's default).
constexpr const char* kDefaultInterpolation = "fourier";

// What a scene that declares no thresholds is judged against (docs/scene-format.md, "Validation
// settings"): the speed and every requested constraint force on the 10° table within 0.5 % of
// their peaks, the accuracy a 10° table reaches on every shipped scene. Without them a
// validation whose every reduced run was 176 % off passed: nothing was judged.
constexpr double kDefaultThresholdGrid_deg = 10.0;
constexpr double kDefaultThresholdMaxError = 0.005;
// The scene's thresholds, or the defaults above when it declares none.
std::vector<models::Threshold> thresholds_of(const models::Scene& scene);

// The reduced run a threshold is judged on: its grid and interpolation, plain m2, rk8pd at
// `tolerance` (the ladder's tightest). Empty when the ladder has no such run.
std::optional<ThresholdResult> judge_threshold(const models::Threshold& th,
                                               const std::vector<RunRecord>& runs,
                                               double tolerance);

// The result for a run made outside the ladder for this threshold.
ThresholdResult judge_threshold_on(const models::Threshold& th, const RunRecord& run);

}  // namespace rdyn::validate
