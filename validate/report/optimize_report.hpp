// The outputs of `rdyn optimize`, rendered from its summary record: summary.json (with the
// curves over the independent coordinate's angle, so a report can be redrawn from it alone),
// profile.csv, the gnuplot scripts and their SVGs, and a self-contained report.html.
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "validate/analysis/optimize.hpp"

namespace rdyn::validate {

// The summary record (summary.json): peaks before/after for both models, reduction, cadence,
// power, amplitude, coefficients, evaluations, optimiser, wall time, agreement, curves.
nlohmann::json optimize_summary(const OptimizeResult& r);

// profile.csv from the summary: q_deg, then per design load <load>_constant, <load>_optimised
// [N·m or N, applied, gated], then F_<force>_{constant,optimised}_{reduced,full} [N].
std::string optimize_profile_csv(const nlohmann::json& summary);

// report.html from the summary and the SVG text of the figures (name → SVG; missing: a note).
std::string render_optimize_html(const nlohmann::json& summary, const std::map<std::string, std::string>& figures);

// Writes summary.json, profile.csv, the scripts, the SVGs (gnuplot spawned without a shell) and
// report.html into `dir` (a folder being written).
void render_optimize_report(const nlohmann::json& summary, const std::string& dir);

}  // namespace rdyn::validate
