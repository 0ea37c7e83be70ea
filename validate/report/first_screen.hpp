// The first screen of a validation report, drawn from summary.json alone: the status and what
// decided it, one recommended reduced setting with its errors and its speed against the cheapest
// full run at equal or better error, the baselines and the error budget of that same setting; and
// the plain-words headline the CLI prints. Issue #23: that screen once named three settings and
// three speedups (the verdict's recommended run, the headline's matched-error pair and a 10° run
// judged beside them); now every number on it belongs to the one recommended setting, and the
// other runs are described where they are drawn (figures 2 and 3, the runs table).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace rdyn::validate {

// The "Verdict" section: recommended setting and speedup, the thresholds' outcome in one line,
// its errors against the target, the baselines and the error budget.
std::string first_screen_html(const nlohmann::json& summary);

// One-paragraph plain-words headline of the recommended setting (also printed by the CLI).
std::string headline(const nlohmann::json& summary);

// Under figure 2: the reduced run drawn there (the 10° default setting) and its errors.
std::string showcase_note(const nlohmann::json& summary);

// Under figure 3: the pair at the matched-error target (the cheapest full run within it and the
// cheapest reduced run as accurate), the speedup quoted across scenes (summary
// "speedup_at_matched_error").
std::string matched_target_note(const nlohmann::json& summary);

}  // namespace rdyn::validate
