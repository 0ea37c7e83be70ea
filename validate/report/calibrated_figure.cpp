#include "validate/report/calibrated_figure.hpp"

#include <fmt/format.h>

#include <cmath>

#include "validate/io/escape.hpp"
#include "validate/report/report_tables.hpp"

namespace rdyn::validate {

namespace {
using json = nlohmann::json;
using namespace report_format;
}  // namespace

std::string calibrated_run_csv(const json& c) { return table_csv(c.at("curve")); }

std::string calibrated_run_gp(const json& c) {
  const bool force = !str(c, "force_name").empty();
  std::string gp = fmt::format(
      "# Both models at the calibrated operating point (rdyn calibrate --write-scene, then simulate). Data: "
      "calibrated.csv.\n"
      "set terminal svg size 960,{} dynamic enhanced font 'sans,11' background rgb 'white'\n"
      "set output 'calibrated.svg'\nset datafile separator ','\nset grid\nset xlabel 't [s]'\n"
      "set multiplot layout {},1 title {} noenhanced\n"
      "set title 'q̇ [rad/s or m/s]'\nplot 'calibrated.csv' skip 1 using 1:2 with lines lw 3 lc rgb '#aaaaaa' title "
      "'full', '' skip 1 using 1:3 with lines lw 1 lc rgb '#d62728' title 'reduced'\n",
      force ? 560 : 320, force ? 2 : 1,
      gnuplot_quoted(fmt::format("At the calibrated operating point, {} rev/s", num(d(c, "cadence_hz")))));
  if (force)
    gp += "set title " + gnuplot_quoted(str(c, "force_name") + " [N]") +
          " noenhanced\nplot 'calibrated.csv' skip 1 using 1:4 with lines lw 3 lc rgb '#aaaaaa' title 'full', '' "
          "skip 1 using 1:5 with lines lw 1 lc rgb '#d62728' title 'reduced'\n";
  return gp + "unset multiplot\n";
}

std::string calibrated_run_section(const json& c, const std::map<std::string, std::string>& figures) {
  // The grid the calibration ran on (summaries before it was recorded: 10°).
  const double grid = std::isfinite(d(c, "grid_deg")) ? d(c, "grid_deg") : 10.0;
  std::string h = fmt::format(
      "<p>Both models at the calibrated operating point: the calibrated load, started on the reduced steady cycle, "
      "over two revolutions (full model at tolerance 1e-10; reduced from the {}° table, the calibration's grid, at "
      "1e-10).</p>",
      num(grid));
  const auto it = figures.find("calibrated");
  const auto at = it == figures.end() ? std::string::npos : it->second.find("<svg");
  h += at != std::string::npos ? it->second.substr(at)
                               : std::string("<p class=warn>Figure calibrated.svg could not be rendered (see "
                                             "gnuplot.log).</p>");
  h += fmt::format("<p>Largest differences: q̇ {} of its peak", pct(d(c, "qdot_error")));
  if (!str(c, "force_name").empty()) h += fmt::format(", {} {} of its peak", H(str(c, "force_name")), pct(d(c, "force_error")));
  h += fmt::format("; mean cadence over the two revolutions: full {} Hz, reduced {} Hz.</p>",
                   num(d(c, "mean_cadence_full_hz"), "{:.6f}"), num(d(c, "mean_cadence_reduced_hz"), "{:.6f}"));
  return h;
}

}  // namespace rdyn::validate
