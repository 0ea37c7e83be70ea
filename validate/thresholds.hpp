// Acceptance thresholds of a scene, judged on the run records.
#pragma once

#include <optional>
#include <vector>

#include "validate/run_record.hpp"

namespace rdyn::validate {

// The interpolation a threshold without one is judged at (the tool's default).
constexpr const char* kDefaultInterpolation = "fourier";

// The reduced run a threshold is judged on: its grid and interpolation, plain m2, rk8pd at
// `tolerance` (the ladder's tightest). Empty when the ladder has no such run.
std::optional<ThresholdResult> judge_threshold(const models::Threshold& th,
                                               const std::vector<RunRecord>& runs,
                                               double tolerance);

// The result for a run made outside the ladder for this threshold.
ThresholdResult judge_threshold_on(const models::Threshold& th, const RunRecord& run);

}  // namespace rdyn::validate
