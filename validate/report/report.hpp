// The report of `rdyn validate`, rendered from summary.json alone (validate/harness/summary.hpp): the
// CSVs behind every figure, gnuplot scripts and their SVGs, and a self-contained report.html
// whose first screen is the verdict table. Every string a scene gave is HTML-escaped.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "validate/report/first_screen.hpp"  // headline, printed by the CLI

namespace rdyn::validate {

// Writes summary.json, the figure data and scripts, renders the figures with gnuplot (no
// shell) and writes report.html into `dir` (a folder being written). When gnuplot fails the
// report says so and names the log.
void render_report(const nlohmann::json& summary, const std::string& dir);

// report.html from the summary and the SVG text of each figure (name → SVG; a missing one
// is reported as not rendered).
std::string render_html(const nlohmann::json& summary,
                        const std::map<std::string, std::string>& figures);


}  // namespace rdyn::validate
