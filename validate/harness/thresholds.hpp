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
// settings"): the speed, every requested constraint force and every joint output the reduced
// model gives, within 0.5 % of their peaks, on the table rdyn's commands take by default (10°,
// halved while it does not resolve the mechanism: validate/analysis/build_reduced's
// extract_resolving) — the accuracy that table reaches on every shipped scene. Without defaults a
// validation whose every reduced run was 176 % off passed: nothing was judged; judged at 10°, a
// five-bar geared 6:1 failed (q̇ 61 % off) although every command runs it on 2.5° within 1e-5,
// and with only the speed and the first force judged, a scene passed while its reactions missed.
constexpr double kDefaultThresholdGrid_deg = 10.0;
constexpr double kDefaultThresholdMaxError = 0.005;
// The scene's thresholds, or when it declares none the defaults above on `judged` (the quantities
// the validation compares: qdot, the constraint forces, the joint outputs both models give) at
// `default_grid_deg`. mean_qdot is not judged by default (a range mechanism's mean speed is ~0).
std::vector<models::Threshold> thresholds_of(const models::Scene& scene, const std::vector<std::string>& judged,
                                             double default_grid_deg);

// The reduced run a threshold is judged on: its grid and interpolation, plain m2, rk8pd at
// `tolerance` (the ladder's tightest). Empty when the ladder has no such run.
std::optional<ThresholdResult> judge_threshold(const models::Threshold& th,
                                               const std::vector<RunRecord>& runs,
                                               double tolerance);

// The result for a run made outside the ladder for this threshold.
ThresholdResult judge_threshold_on(const models::Threshold& th, const RunRecord& run);

}  // namespace rdyn::validate
