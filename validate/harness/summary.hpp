// summary.json: every record of one validation in plain JSON — the numbers, the verdicts and
// the data behind every figure — so the report can be rendered (and re-rendered) from it alone.
#pragma once

#include <nlohmann/json.hpp>

#include "validate/harness/harness.hpp"

namespace rdyn::validate {

nlohmann::json summary_json(const ValidationResult& v);

// One run record (also used by the suite index).
nlohmann::json run_json(const RunRecord& r);

}  // namespace rdyn::validate
