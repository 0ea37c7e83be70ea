// Writes the outputs of `rdyn validate`: summary.json, the CSVs behind every figure, the
// gnuplot scripts and their SVGs, and a self-contained report.html.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "validate/harness.hpp"
#include "validate/output_dir.hpp"

namespace rdyn::validate {

nlohmann::json summary_json(const ValidationResult& v);

// Everything for one scene into `dir` (a folder being written). Figures need gnuplot;
// when it fails the report says so and names the log.
void write_validation_report(const ValidationResult& v, const std::string& dir);

// One-paragraph plain-words headline (also printed by the CLI).
std::string headline(const ValidationResult& v);

}  // namespace rdyn::validate
