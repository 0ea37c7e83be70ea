// Command-line options that several rdyn subcommands share, declared once so that their names,
// help and checks stay the same in every command (CLI11; used by validate/cli/main.cpp only, so the
// rdyn_validate_cli library does not depend on CLI11).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "validate/cli/decimal_number.hpp"

namespace rdyn::validate {

inline constexpr const char* kForceHelpDir =
    "Write into an existing folder that holds files rdyn did not write (same-named files are replaced, nothing else "
    "is touched). Without it such a folder is refused; an earlier rdyn output is replaced atomically.";
inline constexpr const char* kForceHelpFile = "Replace an existing file that rdyn did not write";

// --cadence-hz F and --power-w P, the operating point calibrate and optimize hold. Each records
// whether it was typed: an untyped one falls back to the scene's validation.calibrate block
// (calibration_options_of), so the defaults in the variables are only the last resort. Ranges are
// checked by the command, which names the option and the scene (exit 2).
inline void add_operating_point_options(CLI::App& cmd, double& cadence_hz, bool& cadence_given, double& power_w,
                                        bool& power_given) {
  cmd.add_option_function<double>(
      "--cadence-hz", [&cadence_hz, &cadence_given](const double& v) { cadence_hz = v, cadence_given = true; },
      "Target mean rate [rev/s] (default: the scene's validation.calibrate, else 1)");
  cmd.add_option_function<double>(
      "--power-w", [&power_w, &power_given](const double& v) { power_w = v, power_given = true; },
      "Power the resistance dissipates at that cadence [W] (default: the scene's validation.calibrate; none: the "
      "resistances stay as given)");
}

// --grid-deg and --interp of a reduced table extracted for the command (range checked by the command).
inline void add_reduced_table_options(CLI::App& cmd, double& grid_deg, std::string& interpolation) {
  cmd.add_option("--grid-deg", grid_deg, "Reduced table grid [deg] (default 10)");
  cmd.add_option("--interp", interpolation, "Reduced table interpolation (default fourier)")
      ->check(CLI::IsMember({"cubic", "akima", "linear", "fourier"}));
}

// --set key.path=value, repeatable: scalar overrides of the scene (models/scene_yaml.hpp).
inline void add_scene_overrides(CLI::App& cmd, std::vector<std::string>& sets) {
  cmd.add_option("--set", sets, "Override a scalar of the scene: key.path=value (repeatable)");
}

// --out DIR (required) and --force: an output folder written through validate/io/output_dir.
inline void add_output_folder(CLI::App& cmd, std::string& out, bool& force) {
  cmd.add_option("--out", out, "Output folder (written atomically)")->required();
  cmd.add_flag("--force", force, kForceHelpDir);
}

// Every number option of `app` and its subcommands (and their option groups) reads its text as
// a scene number: decimal only, nothing a double cannot hold (validate/cli/decimal_number.hpp). Called
// once after every option is declared, so no option is forgotten; the check sees the text as
// typed, before CLI11 converts it, and its refusal names the option (exit 2).
inline void require_decimal_numbers(CLI::App& app) {
  for (CLI::Option* o : app.get_options()) {
    const std::string type = o->get_type_name();
    const bool whole = type == "INT" || type == "UINT";
    if (!whole && type != "FLOAT") continue;
    o->check(CLI::Validator([whole](std::string& text) { return check_decimal_number(text, whole); }, ""));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) require_decimal_numbers(*sub);
}

}  // namespace rdyn::validate
