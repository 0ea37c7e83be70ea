// The validate report's drive figure (issue #25): the drive both models need over one revolution
// at the scene's cadence (validate/harness/harness.hpp, calc_drive_cycle), rendered from
// summary.json's "drive_cycle" record alone (validate/harness/summary.cpp): its data (drive.csv),
// its gnuplot script (drive.gp → drive.svg) and the report's section.
#pragma once

#include <map>
#include <string>

#include <nlohmann/json.hpp>

namespace rdyn::validate {

// drive.csv: q_deg, t, drive_full_Nm, drive_reduced_Nm on the record's 1° rows.
std::string drive_cycle_csv(const nlohmann::json& drive_cycle);

// drive.gp: both models' drive against q (top) and their difference (bottom), into drive.svg.
std::string drive_cycle_gp(const nlohmann::json& drive_cycle);

// The report's section: the figure (`figures["drive"]`, else a note that it was not rendered)
// and a table of each model's RMS, peak and mean drive and mean and peak power with their
// differences. Every string from the record is HTML-escaped.
std::string drive_cycle_section(const nlohmann::json& drive_cycle, const std::map<std::string, std::string>& figures);

}  // namespace rdyn::validate
