#include "validate/report/drive_figure.hpp"

#include <cmath>

#include <fmt/format.h>

#include "validate/io/escape.hpp"
#include "validate/report/report_tables.hpp"

namespace rdyn::validate {

namespace {

using json = nlohmann::json;

// A number of the record; NaN for null or a missing key ("not measured").
double number(const json& j, const char* key) {
  return j.contains(key) && j.at(key).is_number() ? j.at(key).get<double>() : NAN;
}

std::string shown(double x, const char* spec = "{:.4g}") {
  return std::isfinite(x) ? fmt::format(fmt::runtime(spec), x) : "n/a";
}

}  // namespace

std::string drive_cycle_csv(const json& c) { return report_format::table_csv(c.at("curve")); }

std::string drive_cycle_gp(const json& c) {
  const std::string title = fmt::format("Drive over one revolution at {} rev/s (every load of the scene applied)",
                                        shown(number(c, "cadence_hz"), "{:g}"));
  return "# The drive each model needs to turn at a constant rate (rdyn drive --cadence-hz F). Data: drive.csv.\n"
         "set terminal svg size 960,560 dynamic enhanced font 'sans,11' background rgb 'white'\n"
         "set output 'drive.svg'\nset datafile separator ','\nset grid\nset xlabel 'q [deg]'\n"
         "set multiplot layout 2,1 title " +
         gnuplot_quoted(title) +
         " noenhanced\n"
         "set title 'drive [N·m]'\nplot 'drive.csv' skip 1 using 1:3 with lines lw 3 lc rgb '#aaaaaa' title "
         "'full (inverse dynamics)', '' skip 1 using 1:4 with lines lw 1 lc rgb '#d62728' title "
         "'reduced (Eksergian, 10° table)'\n"
         "set title 'reduced − full [N·m]'\nplot 'drive.csv' skip 1 using 1:($4-$3) with lines lc rgb '#1f77b4' "
         "notitle\nunset multiplot\n";
}

std::string drive_cycle_section(const json& c, const std::map<std::string, std::string>& figures) {
  std::string h = fmt::format(
      "<h2>Drive at the scene's cadence</h2><p>The generalized force a drive on q must add for the mechanism "
      "to turn at a constant {} rev/s from q = {}° with every other load of the scene applied "
      "(<code>rdyn drive SCENE --cadence-hz {}</code>), over one revolution on 1° rows: the full model by "
      "inverse dynamics, the reduced model by Eksergian's equation solved for the drive.</p>",
      shown(number(c, "cadence_hz"), "{:g}"), shown(number(c, "q0_deg"), "{:g}"),
      shown(number(c, "cadence_hz"), "{:g}"));
  const auto it = figures.find("drive");
  h += it != figures.end() && !it->second.empty()
           ? it->second
           : std::string("<p class=warn>Figure drive.svg could not be rendered (see gnuplot.log).</p>");
  const json& f = c.value("full", json::object());
  const json& r = c.value("reduced", json::object());
  auto row = [&](const char* what, const char* key, const char* unit) {
    const double a = number(f, key), b = number(r, key);
    return fmt::format("<tr><td class=l>{} [{}]</td><td>{}</td><td>{}</td><td>{}</td></tr>", what, unit, shown(a),
                       shown(b), shown(b - a, "{:+.3g}"));
  };
  h += "<table><tr><th></th><th>full</th><th>reduced</th><th>reduced − full</th></tr>" +
       row("RMS drive", "rms_Nm", "N·m") + row("peak |drive|", "peak_Nm", "N·m") +
       row("mean drive", "mean_Nm", "N·m") + row("mean power", "mean_power_W", "W") +
       row("peak power", "peak_power_W", "W") + "</table>";
  if (std::isfinite(number(c, "grid_deg")) && number(c, "grid_deg") > 0)
    h += fmt::format("<p>The reduced model on a {}° table (as <code>rdyn drive</code> takes it: 10°, halved where "
                     "that does not resolve the mechanism).</p>",
                     shown(number(c, "grid_deg"), "{:g}"));
  h += fmt::format("<p>Largest difference along the revolution {} N·m ({} of the full model's peak).</p>",
                   shown(number(c, "max_abs_difference_Nm"), "{:.3g}"),
                   std::isfinite(number(c, "max_abs_difference_rel_peak"))
                       ? fmt::format("{:.3g} %", 100 * number(c, "max_abs_difference_rel_peak"))
                       : std::string("n/a"));
  return h;
}

}  // namespace rdyn::validate
