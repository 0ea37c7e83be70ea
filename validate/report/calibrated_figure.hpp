// The validate report's figure of the calibrated operating point (issue #23: the report's
// figures showed the scene's own loads, not the operating point its calibration found): both
// models over two revolutions from the reduced steady cycle at the calibrated load, rendered from
// summary.json's "calibrated_run" record alone (validate/harness/calibrated_run.hpp).
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

namespace rdyn::validate {

// calibrated.csv: t, qdot_full, qdot_reduced[, force_full_N, force_reduced_N].
std::string calibrated_run_csv(const nlohmann::json& calibrated_run);

// calibrated.gp: the speed (top) and the first constraint force (bottom) of both models against
// t, into calibrated.svg.
std::string calibrated_run_gp(const nlohmann::json& calibrated_run);

// The part of the calibration section: the figure (`figures["calibrated"]`, else a note that it
// was not rendered) and the two models' differences and mean cadences.
std::string calibrated_run_section(const nlohmann::json& calibrated_run,
                                   const std::map<std::string, std::string>& figures);

}  // namespace rdyn::validate
