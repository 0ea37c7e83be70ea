#include "validate/report/report.hpp"
#include "validate/report/cycle_animation.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

#include "validate/io/escape.hpp"
#include "validate/report/calibrated_figure.hpp"
#include "validate/report/drive_figure.hpp"
#include "validate/report/first_screen.hpp"
#include "validate/report/report_tables.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/io/run_program.hpp"

namespace rdyn::validate {

namespace {

using json = nlohmann::json;

using namespace report_format;

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

const char* kSvgHead =
    "set terminal svg size 960,{} dynamic enhanced font 'sans,11' background rgb 'white'\n";

// Figure 1: reduced parameters — samples and interpolant.
std::string params_gp(const json& fig) {
  const auto& names = fig.at("params_samples").at("names");
  const size_t nf = names.size() > 3 ? (names.size() - 3) / 2 : 0;
  std::string gp =
      "# Reduced parameters vs the independent coordinate. Restyle freely; data: params.csv "
      "(table\n"
      "# samples), params_dense.csv (the interpolant at 1°).\n";
  gp += fmt::format(fmt::runtime(kSvgHead), nf ? 640 : 330);
  gp += fmt::format(
      "set output 'params.svg'\nset datafile separator ','\nset grid\nset key bottom right\n"
      "set xlabel '{}'\n{}set multiplot layout {},2 title 'Reduced parameters "
      "(points: samples from kinetostatic calls; lines: interpolant)'\n",
      names[0] == "q_m" ? "q [m]" : "q [deg]", names[0] == "q_m" ? "" : "set xtics 60\n", nf ? 2 : 1);
  for (size_t c = 1; c < names.size(); ++c) {
    const std::string unit = c <= 2 ? "kg·m^2" : "kg·m";
    gp += fmt::format(
        "set title {} noenhanced\nplot 'params_dense.csv' skip 1 using 1:{} with lines lw 2 lc rgb "
        "'#1f77b4' "
        "title 'interpolant', 'params.csv' skip 1 using 1:{} with points pt 7 ps 0.6 lc rgb "
        "'#d62728' title "
        "'samples'\n",
        gnuplot_quoted(names[c].get<std::string>() + " [" + unit + "]"), c + 1, c + 1);
  }
  return gp + "unset multiplot\n";
}

// Figure 2: the speed and the first constraint force, full and reduced, over the last periods.
std::string timeseries_gp(const json& ts) {
  const bool has_f = ts.at("names").size() >= 5;
  std::string gp =
      "# Full model and reduced model over the last periods of the scene's time scale. Data: "
      "compare.csv.\n";
  gp += fmt::format(fmt::runtime(kSvgHead), 640);
  gp +=
      "set output 'timeseries.svg'\nset datafile separator ','\nset grid\nset xlabel 't [s]'\n"
      "set multiplot layout 2,2 title " +
      gnuplot_quoted("Full model (Simbody) and reduced model (" +
                     ts.value("reduced_run", std::string()) + ")") +
      " noenhanced\n"
      "set title 'speed of the independent coordinate [rad/s]'\nplot 'compare.csv' skip 1 using "
      "1:2 with lines lw 3 "
      "lc rgb '#aaaaaa' title 'full', '' skip 1 using 1:3 with lines lw 1 lc rgb '#d62728' title "
      "'reduced'\n"
      "set title 'reduced − full [rad/s]'\nplot 'compare.csv' skip 1 using 1:($3-$2) with lines lc "
      "rgb '#1f77b4' "
      "notitle\n";
  if (has_f)
    gp += fmt::format(
        "set title {0} noenhanced\nplot 'compare.csv' skip 1 using 1:4 with lines lw 3 lc rgb "
        "'#aaaaaa' "
        "title 'full', '' skip 1 using 1:5 with lines lw 1 lc rgb '#d62728' title 'reduced'\n"
        "set title 'reduced − full [N]'\nplot 'compare.csv' skip 1 using 1:($5-$4) with lines lc "
        "rgb '#1f77b4' notitle\n",
        gnuplot_quoted(ts.value("force_name", std::string()) + " force [N]"));
  return gp + "unset multiplot\n";
}

// Figure 2b: every requested reaction and the shaking load, full (grey) and reduced (red) where
// the reduced model gives it, one panel each, two panels a row. Data: joint_outputs.csv.
std::string joint_outputs_gp(const json& jo) {
  const auto& names = jo.at("names");
  std::vector<std::pair<std::string, int>> panels;  // column name, its _full column (1-based)
  for (size_t c = 1; c < names.size(); ++c) {
    const std::string n = names[c].get<std::string>();
    if (n.size() > 5 && n.compare(n.size() - 5, 5, "_full") == 0) panels.emplace_back(n.substr(0, n.size() - 5), c + 1);
  }
  const size_t rows = (panels.size() + 1) / 2;
  std::string gp = "# Requested reactions and shaking load, full and reduced model. Data: joint_outputs.csv.\n";
  gp += fmt::format(fmt::runtime(kSvgHead), 60 + 220 * rows);
  gp += fmt::format(
      "set output 'joint_outputs.svg'\nset datafile separator ','\nset grid\nset xlabel 't [s]'\n"
      "set multiplot layout {},2\n",
      rows);
  for (size_t p = 0; p < panels.size(); ++p) {
    const auto& [n, col] = panels[p];
    const bool reduced = col < static_cast<int>(names.size()) && names[col].get<std::string>() == n + "_reduced";
    const std::string unit = n.size() > 2 && n.compare(n.size() - 2, 2, "_M") == 0 ? "N·m" : "N";
    gp += fmt::format("set title {} noenhanced\nplot 'joint_outputs.csv' skip 1 using 1:{} with lines lw 3 lc rgb "
                      "'#aaaaaa' title 'full'",
                      gnuplot_quoted(n + " [" + unit + "]" + (reduced ? "" : " (full model only)")), col);
    if (reduced) gp += fmt::format(", '' skip 1 using 1:{} with lines lw 1 lc rgb '#d62728' title 'reduced'", col + 1);
    gp += "\n";
  }
  return gp + "unset multiplot\n";
}

// Figure 3 data and script: error of the headline quantity against cost, every run.
void write_pareto(const json& s, const std::string& dir) {
  const std::string Q = str(s, "headline_quantity");
  std::string red = "wall_s,error,label\n", front = red, full = red;
  std::vector<std::pair<double, std::string>> fr;
  for (const auto& r : s.at("runs")) {
    const double w = d(r, "wall_s"), e = error_of(r, Q);
    if (!std::isfinite(w) || !std::isfinite(e)) continue;  // stopped runs have no error to plot
    const std::string line =
        fmt::format("{:.6g},{:.6g},{}\n", w, std::max(e, 1e-12), csv_field(str(r, "label")));
    (str(r, "model") == "full" ? full : red) += line;
    if (str(r, "model") == "reduced" && r.value("pareto", false)) fr.push_back({w, line});
  }
  std::sort(fr.begin(), fr.end());
  for (const auto& p : fr) front += p.second;
  write_text_file(dir + "/pareto_reduced.csv", red);
  write_text_file(dir + "/pareto_front.csv", front);
  write_text_file(dir + "/pareto_full.csv", full);
  // Peer engines' ladders (summary.json "peers"), one series each, files by index.
  std::string peer_plots;
  const json peers = s.value("peers", json::array());
  for (size_t i = 0; i < peers.size(); ++i) {
    std::string csv = "wall_s,error,label\n";
    for (const auto& r : peers[i].value("runs", json::array())) {
      const double w = d(r, "wall_s"), e = error_of(r, Q);
      if (std::isfinite(w) && std::isfinite(e))
        csv += fmt::format("{:.6g},{:.6g},{}\n", w, std::max(e, 1e-12), csv_field(str(r, "label")));
    }
    write_text_file(dir + fmt::format("/pareto_peer{}.csv", i), csv);
    peer_plots += fmt::format(", 'pareto_peer{}.csv' skip 1 using 1:2 with linespoints pt {} lw 2 title {}", i, 8 + i,
                              gnuplot_quoted(str(peers[i], "engine") + " " + str(peers[i], "integrator") +
                                             " (fixed steps)"));
  }
  write_text_file(
      dir + "/pareto.gp",
      fmt::format("# Error of {0} (max over the compared window, relative to its peak) against "
                  "computing time\n"
                  "# for the run as simulated. Data: pareto_reduced.csv, pareto_front.csv, "
                  "pareto_full.csv.\n",
                  Q) +
          fmt::format(fmt::runtime(kSvgHead), 560) +
          fmt::format(
              "set output 'pareto.svg'\nset datafile separator ','\nset grid\nset logscale xy\n"
              "set format x '10^{{%L}}'\nset format y '10^{{%L}}'\n"
              "set xlabel {2} noenhanced\nset ylabel {1} noenhanced\n"
              "set title 'Accuracy against cost: every reduced run, its Pareto front, and the "
              "full-model "
              "tolerance ladder'\nset key outside right\n"
              "plot 'pareto_reduced.csv' skip 1 using 1:2 with points pt 6 ps 0.6 lc rgb '#999999' "
              "title "
              "'reduced runs', 'pareto_front.csv' skip 1 using 1:2 with linespoints pt 7 lw 2 lc "
              "rgb '#d62728' "
              "title 'reduced Pareto front', 'pareto_full.csv' skip 1 using 1:2 with linespoints "
              "pt 5 lw 2 lc "
              "rgb '#1f77b4' title 'full model (tolerance ladder)'{3}, {0:g} with lines dt 2 lc rgb "
              "'#555555' "
              "title 'matched-error target'\n",
              // A hand-edited summary without it: the harness's default (ValidationResult).
              std::isfinite(d(s, "matched_error_target")) ? d(s, "matched_error_target") : 1e-3,
              gnuplot_quoted(Q + " error / peak"),
              gnuplot_quoted(
                  fmt::format("computing time for the {} s run [s]", num(d(s, "duration_s")))),
              peer_plots));
}

// How the baselines were run (fair timing) and the peers' speedups, under figure 3.
std::string baselines_note(const json& s) {
  std::string h;
  if (s.contains("full_model_timing")) h += "<p>" + H(str(s, "full_model_timing")) + "</p>";
  for (const auto& p : s.value("peers", json::array())) {
    h += "<p>" + H(str(p, "how")) + " ";
    const json& sp = p.contains("speedup_at_matched_error") ? p.at("speedup_at_matched_error") : json(nullptr);
    if (sp.is_number() && p.at("matched_peer").is_object() && p.at("matched_reduced").is_object()) {
      h += fmt::format("At matched {} error the reduced model ({}) is {:.3g}× faster than {} ({}), counting "
                       "integration only",
                       H(str(s, "headline_quantity")), H(str(p.at("matched_reduced"), "label")), sp.get<double>(),
                       H(str(p, "engine")), H(str(p.at("matched_peer"), "label")));
      // Its table is extracted once per mechanism: say what that costs beside one run.
      for (const auto& e : s.value("extractions", json::array()))
        if (d(e, "grid_deg") == d(p.at("matched_reduced"), "grid_deg"))
          h += fmt::format("; its {}° table costs {} ms to extract once", num(d(e, "grid_deg")), num(d(e, "ms")));
      h += ".";
    } else {
      h += "No speedup is claimed over this ladder (no run within the matched-error target, or no reduced run as "
           "accurate).";
    }
    h += "</p>";
  }
  return h;
}

// Figure 4 data and script: error against grid step per interpolation.
void write_convergence(const json& s, const std::string& dir) {
  const auto& conv = s.at("convergence");
  std::vector<double> grids;
  for (const auto& e : s.at("extractions"))
    if (std::isfinite(d(e, "grid_deg"))) grids.push_back(d(e, "grid_deg"));
  std::string csv = "grid_deg";
  for (const auto& ser : conv.at("series")) csv += "," + csv_field(str(ser, "interpolation"));
  csv += "\n";
  for (double g : grids) {
    csv += fmt::format("{:g}", g);
    for (const auto& ser : conv.at("series")) {
      std::string cell;
      for (const auto& p : ser.at("points"))
        if (p.is_array() && p.size() == 2 && p[0].is_number() &&
            std::abs(p[0].get<double>() - g) < 1e-9 && p[1].is_number())
          cell = fmt::format("{:.6g}", std::max(p[1].get<double>(), 1e-12));
      csv += "," + cell;
    }
    csv += "\n";
  }
  write_text_file(dir + "/convergence.csv", csv);
  const std::string Q = str(conv, "quantity");
  std::string gp =
      "# Error against grid step (rk8pd at the ladder's tightest tolerance). Data: "
      "convergence.csv.\n" +
      fmt::format(fmt::runtime(kSvgHead), 560) +
      "set output 'convergence.svg'\nset datafile separator ','\nset grid\nset logscale xy\n"
      "set format y '10^{%L}'\nset xlabel 'grid step [deg]'\nset ylabel " +
      gnuplot_quoted(Q + " error / peak") +
      " noenhanced\nset key outside right\nset title 'Convergence with the grid (slopes: observed "
      "order, fitted above 10× the reference floor)'\n";
  const char* colors[] = {"#1f77b4", "#2ca02c", "#9467bd", "#d62728", "#ff7f0e", "#8c564b"};
  std::string plot;
  for (size_t k = 0; k < conv.at("series").size(); ++k) {
    const auto& ser = conv.at("series")[k];
    const double o = d(ser, "order");
    plot += fmt::format(
        "{}'convergence.csv' skip 1 using 1:{} with linespoints pt 7 lw 2 lc rgb '{}' title {}",
        k ? ", " : "", k + 2, colors[k % 6],
        gnuplot_quoted(str(ser, "interpolation") + " (order " +
                       (std::isfinite(o) ? fmt::format("{:.1f}", o) : "n/a") + ")"));
  }
  if (!plot.empty()) gp += "plot " + plot + "\n";
  write_text_file(dir + "/convergence.gp", gp);
}

void write_runs_csv(const json& s, const std::string& dir) {
  std::string csv =
      "model,label,grid_deg,interpolation,energy_consistent,integrator,tolerance,fixed_step_s,wall_"
      "s,"
      "repeats,steps,energy_residual_rel,pareto,excluded_samples,failure";
  for (const auto& q : s.at("quantities"))
    csv += "," + csv_field("max_rel_" + q.get<std::string>()) + "," +
           csv_field("rms_rel_" + q.get<std::string>());
  csv += "\n";
  auto cell = [](double x) { return std::isfinite(x) ? fmt::format("{:.6g}", x) : std::string(); };
  for (const auto& r : s.at("runs")) {
    csv += fmt::format(
        "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csv_field(str(r, "model")),
        csv_field(str(r, "label")), cell(d(r, "grid_deg")), csv_field(str(r, "interpolation")),
        r.value("energy_consistent_m2", false) ? 1 : 0, csv_field(str(r, "integrator")),
        cell(d(r, "tolerance")), cell(d(r, "fixed_step_s")), cell(d(r, "wall_s")),
        r.value("repeats", 0), r.value("steps", 0L), cell(d(r, "energy_balance_residual_rel")),
        r.value("pareto", false) ? 1 : 0, r.value("excluded_between_switches", 0L),
        csv_field(str(r, "failure")));
    for (const auto& q : s.at("quantities")) {
      const std::string name = q.get<std::string>();
      const json e = r.contains("errors") && r.at("errors").contains(name) ? r.at("errors")[name]
                                                                           : json::object();
      csv += "," + cell(d(e, "max_rel")) + "," + cell(d(e, "rms_rel"));
    }
    csv += "\n";
  }
  write_text_file(dir + "/runs.csv", csv);
}

std::string svg_or_note(const std::map<std::string, std::string>& figures,
                        const std::string& name) {
  const auto it = figures.find(name);
  const auto at = it == figures.end() ? std::string::npos : it->second.find("<svg");
  if (at == std::string::npos)
    return fmt::format("<p class=warn>Figure {}.svg could not be rendered (see gnuplot.log).</p>",
                       name);
  return it->second.substr(at);
}

// Published values the scene compares with (validation.compare), beside rdyn's calibration.
std::string calibration_section(const json& s) {
  const auto& c = s.at("calibration");
  std::string h = "<h2>Calibration</h2>";
  const bool with_power = c.contains("target_power_w") && c.at("target_power_w").is_number();
  const std::string unit = c.value("load_unit", std::string("N·m"));
  const std::string load = c.value("load", std::string());
  const double value = c.contains("load_value") ? d(c, "load_value") : d(c, "drive_torque_Nm");
  const double per_unit =
      c.contains("work_per_rev_per_unit") ? d(c, "work_per_rev_per_unit") : d(c, "drive_work_per_rev_per_Nm");
  h += fmt::format(
      "<p>{}, the drive load {}({}) that holds a mean steady rate of {} Hz is <b>{} {}</b> (reduced model: {} Hz; "
      "confirmed with the full model: {} Hz). Its mean power {} W, speed fluctuation {}{}. ",
      with_power ? fmt::format("With the resistance dissipating {} W at {} Hz", num(d(c, "target_power_w")),
                               num(d(c, "target_cadence_hz")))
                 : std::string("With the resistances as the scene gives them"),
      load.empty() ? std::string() : "<b>" + H(load) + "</b> ", H(c.value("load_kind", std::string("joint_torques"))),
      num(d(c, "target_cadence_hz")), num(value, "{:.4g}"), H(unit), num(d(c, "mean_cadence_hz_reduced"), "{:.6f}"),
      num(d(c, "mean_cadence_hz_full"), "{:.6f}"), num(d(c, "mean_power_W"), "{:.4g}"),
      pct(d(c, "speed_fluctuation")),
      str(c, "force_name").empty() ? std::string()
                                   : fmt::format(", peak {} force {} N", H(str(c, "force_name")),
                                                 num(d(c, "peak_force_N"), "{:.4g}")));
  if (with_power)
    h += fmt::format("At steady state the drive's work per revolution equals the dissipated energy, {} J; ",
                     num(d(c, "target_power_w") / d(c, "target_cadence_hz"), "{:.4g}"));
  h += fmt::format("at the target rate the load does {} J per revolution per {}.</p>", num(per_unit, "{:.4g}"),
                   H(unit));
  for (const auto& cv : c.value("compare", json::array())) {
    const double ours = d(cv, "rdyn_value"), theirs = d(cv, "value");
    h += fmt::format("<p><b>{}</b>: rdyn {} {}, {} {} {}", H(str(cv, "quantity")),
                     num(ours, "{:.4g}"), H(str(cv, "unit")),
                     H(str(cv, "source").empty() ? "published" : str(cv, "source")),
                     num(theirs, "{:.4g}"), H(str(cv, "unit")));
    if (std::isfinite(ours) && std::isfinite(theirs) && theirs != 0)
      h += fmt::format(" ({:+.3g} %)", 100 * (ours - theirs) / theirs);
    if (str(cv, "quantity") == "drive_torque_Nm" && theirs > 0 && with_power)
      h += "; the published value would do " +
           num(d(c, "target_power_w") / d(c, "target_cadence_hz") / theirs, "{:.4g}") +
           " J per revolution per N·m to balance the same energy";
    h += ".</p>";
    if (!str(cv, "explanation").empty()) h += "<p>" + H(str(cv, "explanation")) + "</p>";
  }
  return h;
}

}  // namespace

std::string render_html(const json& s, const std::map<std::string, std::string>& figures) {
  std::string h;
  h += html_head(str(s, "scene"));
  const bool pass = str(s, "status") == "pass";
  h += "<h1>rdyn validation: " + H(str(s, "scene")) +
       " — <span class=" + (pass ? "pass>pass" : "fail>FAIL") + "</span></h1>";
  if (!s.at("failures").empty()) {
    h += "<ul>";
    for (const auto& f : s.at("failures"))
      h += "<li class=warn>" + H(f.get<std::string>()) + "</li>";
    h += "</ul>";
  }
  h += first_screen_html(s);
  h += "<p class=lead>" + H(headline(s)) + "</p>";
  if (!str(s, "note").empty())
    h += "<p><b>What this scene tests:</b> " + H(str(s, "note")) + "</p>";
  const auto& w = s.at("steady_window");
  h += fmt::format(
      "<p>Scene file: <code>{}</code>. Simulated {} s, output every {} s. Time scale: {}. Compared "
      "window: {}. Samples lying between the two models' instants of a load switch (where the "
      "force "
      "jumps) are excluded from the error maxima and counted in <code>runs.csv</code>.</p>",
      H(str(s, "scene_file")), num(d(s, "duration_s")), num(d(s, "output_interval_s")),
      H(str(s.at("time_scale"), "how")), H(str(w, "how")));
  h += s.value("per_second_measured", false)
           ? "<p>Costs are given for the run as simulated and per simulated second (the run lasted "
             "at least a second).</p>"
           : "<p>Costs are given for the run as simulated only: it lasted less than a second, so a "
             "per-second figure "
             "would be an extrapolation.</p>";
  h += "<h2>1. Reduced parameters</h2><p>m1, m2 of Eksergian's equation <code>m1 q̈ + m2 q̇² = "
       "F*</code> and me1, me2 of "
       "each constraint line <code>me1 q̈ + me2 q̇² = F_E + Q_x</code>, from kinetostatic calls of "
       "the full model at 10°."
       "</p>" +
       (s.contains("figures") && s.at("figures").contains("params_samples")
            ? svg_or_note(figures, "params")
            : "<p>No table in this summary.</p>");
  h += std::string(s.at("steady_window").value("whole_run", false)
                       ? "<h2>2. Full and reduced model toward the end of the run</h2>"
                       : "<h2>2. Full and reduced model over the last periods</h2>") +
       svg_or_note(figures, "timeseries") + showcase_note(s);
  if (s.contains("figures") && s.at("figures").contains("joint_outputs")) {
    h += "<h3>Joint reactions and shaking load</h3><p>The requested reactions (the joint's force on its child, "
         "the loop's force of body_a on body_b, ground frame) and the mechanism's load on the ground, over the "
         "same periods; their errors are in the verdicts and the runs table.</p>" +
         svg_or_note(figures, "joint_outputs");
    for (const auto& r : s.value("reactions_not_given", json::array()))
      h += "<p class=warn>Reaction " + H(str(r, "reaction")) + ": full model only (" + H(str(r, "why")) + ").</p>";
  }
  h += "<h2>3. Accuracy against computing time</h2>" + svg_or_note(figures, "pareto") + matched_target_note(s) + baselines_note(s);
  h += "<h2>4. Convergence with the grid</h2>" + svg_or_note(figures, "convergence");
  h += "<p>Observed orders (fitted above 10× the reference's own change, " +
       pct(d(s.at("convergence"), "floor")) + "):";
  for (const auto& ser : s.at("convergence").at("series")) {
    const double o = d(ser, "order");
    h += fmt::format(" {} {};", H(str(ser, "interpolation")),
                     std::isfinite(o) ? fmt::format("{:.2f}", o) : "n/a");
  }
  h += " Below that floor an error measures the reference, not the table.</p>";
  if (s.contains("calibration")) h += calibration_section(s);
  if (s.contains("calibrated_run")) h += calibrated_run_section(s.at("calibrated_run"), figures);
  if (s.contains("drive_cycle")) h += drive_cycle_section(s.at("drive_cycle"), figures);
  h += thresholds_table(s) + runs_table(s) + extraction_table(s);
  h += "<h2>Files</h2><p><code>summary.json</code> (every number above and the data of every "
       "figure; the report is "
       "rendered from it alone), <code>runs.csv</code>, and for each figure its data "
       "(<code>*.csv</code>) and gnuplot "
       "script (<code>*.gp</code>): edit a script and run <code>gnuplot NAME.gp</code> in this "
       "folder to restyle it.</p>"
       "<p>Machine: " +
       H(str(s, "machine")) + ".</p></body></html>\n";
  return h;
}

void render_report(const json& s, const std::string& dir) {
  write_text_file(dir + "/summary.json", s.dump(2) + "\n");
  write_runs_csv(s, dir);
  std::vector<std::string> names;
  const json& fig = s.value("figures", json::object());
  if (fig.contains("params_samples")) {
    write_text_file(dir + "/params.csv", table_csv(fig.at("params_samples")));
    write_text_file(dir + "/params_dense.csv", table_csv(fig.at("params_dense")));
    write_text_file(dir + "/params.gp", params_gp(fig));
    names.push_back("params");
  }
  if (fig.contains("timeseries")) {
    write_text_file(dir + "/compare.csv", table_csv(fig.at("timeseries")));
    write_text_file(dir + "/timeseries.gp", timeseries_gp(fig.at("timeseries")));
    names.push_back("timeseries");
  }
  if (fig.contains("joint_outputs")) {
    write_text_file(dir + "/joint_outputs.csv", table_csv(fig.at("joint_outputs")));
    write_text_file(dir + "/joint_outputs.gp", joint_outputs_gp(fig.at("joint_outputs")));
    names.push_back("joint_outputs");
  }
  if (s.contains("drive_cycle")) {  // validate/report/drive_figure.hpp
    write_text_file(dir + "/drive.csv", drive_cycle_csv(s.at("drive_cycle")));
    write_text_file(dir + "/drive.gp", drive_cycle_gp(s.at("drive_cycle")));
    names.push_back("drive");
  }
  if (s.contains("calibrated_run")) {  // validate/report/calibrated_figure.hpp
    write_text_file(dir + "/calibrated.csv", calibrated_run_csv(s.at("calibrated_run")));
    write_text_file(dir + "/calibrated.gp", calibrated_run_gp(s.at("calibrated_run")));
    names.push_back("calibrated");
  }
  write_pareto(s, dir);
  write_convergence(s, dir);
  names.insert(names.end(), {"pareto", "convergence"});
  // No shell: gnuplot gets an argument vector and runs in the report's folder (60 s each).
  std::map<std::string, std::string> figures;
  bool gnuplot_ok = true;
  for (const auto& name : names) {
    const auto run = run_program({"gnuplot", name + ".gp"}, dir, dir + "/gnuplot.log", 60.0);
    gnuplot_ok &= run.ok();
    figures[name] = read_text(dir + "/" + name + ".svg");
  }
  std::string html = render_html(s, figures);
  if (!gnuplot_ok) {
    const auto at = html.find("<h2>1.");
    html.insert(at == std::string::npos ? 0 : at,
                "<p class=warn>gnuplot reported errors; see gnuplot.log beside this report.</p>");
  }
  // The mechanism drawn, then one steady cycle animated (validate/report/cycle_animation.hpp).
  if (const std::string mech = mechanism_drawing_html(s) + validate_animation_html(s); !mech.empty()) {
    const auto at = html.find("<h2>1.");
    html.insert(at == std::string::npos ? 0 : at, mech);
  }
  write_text_file(dir + "/report.html", html);
}

}  // namespace rdyn::validate
