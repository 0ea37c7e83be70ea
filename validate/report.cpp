#include "validate/report.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "validate/escape.hpp"
#include "validate/output_dir.hpp"
#include "validate/run_program.hpp"

namespace rdyn::validate {

namespace {

double err(const RunRecord& r, const std::string& q) {
  const auto* s = r.errors.find(q);
  return s ? s->max_rel : NAN;
}

std::string pct(double x) { return std::isfinite(x) ? fmt::format("{:.3g} %", 100 * x) : "n/a"; }
std::string secs(double s) {
  if (s >= 1) return fmt::format("{:.3g} s", s);
  if (s >= 1e-3) return fmt::format("{:.3g} ms", s * 1e3);
  return fmt::format("{:.3g} µs", s * 1e6);
}

void write_text(const std::string& path, const std::string& text) { write_text_file(path, text); }

// Scene-given text in HTML.
std::string H(const std::string& s) { return html_escape(s); }

std::string read_text(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

nlohmann::json comparison_json(const Comparison& c) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& s : c.signals) j[s.name] = {{"max_rel", s.max_rel}, {"rms_rel", s.rms_rel}, {"peak", s.peak}};
  return {{"errors", j}, {"samples", c.samples}, {"excluded_between_switches", c.excluded}};
}

nlohmann::json run_json(const RunRecord& r) {
  nlohmann::json j = {{"label", r.label()},
                      {"model", r.model},
                      {"integrator", r.integrator},
                      {"tolerance", r.tolerance},
                      {"wall_s_median", r.wall_s},
                      {"wall_s_per_simulated_s", r.per_simulated_s},
                      {"repeats", r.repeats},
                      {"steps", r.steps},
                      {"rejected_steps", r.rejected},
                      {"smallest_step_s", r.smallest_step_s},
                      {"events", r.events},
                      {"energy_balance_residual_rel", r.energy_residual_rel},
                      {"cycles", r.cycles},
                      {"energy_drift_per_cycle_J", r.energy_drift_per_cycle_J},
                      {"pareto", r.pareto}};
  if (!r.failure.empty()) j["failure"] = r.failure;
  if (r.model == "full") j["constraint_violation_m"] = r.constraint_violation_m;
  if (r.model == "reduced") {
    j["grid_deg"] = r.grid_deg;
    j["interpolation"] = r.interpolation;
    j["energy_consistent_m2"] = r.energy_consistent;
    if (r.integrator == "rk4-fixed") j["fixed_step_s"] = r.fixed_step_s;
  }
  j.update(comparison_json(r.errors));
  return j;
}

// Least-squares slope of log(error) against log(grid), over errors above the floor.
double observed_order(const std::vector<std::pair<double, double>>& pts, double floor) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (const auto& [g, e] : pts) {
    if (!(e > floor) || !std::isfinite(e)) continue;
    const double x = std::log(g), y = std::log(e);
    sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
  }
  if (n < 2) return NAN;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

const RunRecord* find_run(const ValidationResult& v, double grid, const std::string& interp, bool ec,
                          const std::string& integrator, double tol) {
  const RunRecord* best = nullptr;
  for (const auto& r : v.runs)
    if (r.model == "reduced" && std::abs(r.grid_deg - grid) < 1e-9 && r.interpolation == interp &&
        r.energy_consistent == ec && r.integrator == integrator && (integrator == "rk4-fixed" || r.tolerance == tol))
      best = &r;
  return best;
}

double tightest_reduced_tol(const ValidationResult& v) {
  double t = INFINITY;
  for (const auto& r : v.runs)
    if (r.model == "reduced" && r.integrator == "rk8pd") t = std::min(t, r.tolerance);
  return t;
}

std::vector<double> grids_of(const ValidationResult& v) {
  std::vector<double> g;
  for (const auto& e : v.extractions) g.push_back(e.grid_deg);
  return g;
}

const char* kInterps[] = {"cubic", "akima", "linear", "fourier"};

}  // namespace

std::string headline(const ValidationResult& v) {
  std::string s;
  const std::string q = v.headline_quantity == "qdot" ? "speed" : v.headline_quantity + "-force";
  if (v.speedup_at_matched_error) {
    const auto& f = v.runs[v.matched_full];
    const auto& r = v.runs[v.matched_reduced];
    s += fmt::format(
        "On this machine ({}), the reduced model of '{}' ({}) simulates one second of motion in {} against {} for "
        "Simbody forward dynamics ({}), at equal or better {} error ({} vs {} of its peak): {:.0f}× faster. ",
        v.machine, v.scene, r.label(), secs(r.per_simulated_s), secs(f.per_simulated_s), f.label(), q,
        pct(err(r, v.headline_quantity)), pct(err(f, v.headline_quantity)), *v.speedup_at_matched_error);
    for (const auto& e : v.extractions)
      if (std::abs(e.grid_deg - r.grid_deg) < 1e-9)
        s += fmt::format("Its {:g}° table costs {:.3g} ms to extract once (as long as {:.3g} s of simulated motion with "
                         "the full model). ",
                         e.grid_deg, e.ms, e.ms * 1e-3 / f.per_simulated_s);
  } else {
    s += fmt::format("No run of the full-model tolerance ladder of '{}' reached the {} target of {} of its peak, or no "
                     "reduced run matched it: no matched-error speedup is claimed. ",
                     v.scene, q, pct(v.matched_target));
  }
  s += fmt::format("Extracting the 10° table costs {:.3g} ms. ", v.extraction_ms);
  if (v.showcase_run >= 0) {
    const auto& r = v.runs[v.showcase_run];
    s += fmt::format("At the paper's 10° grid ({}), the errors are {} for the speed", r.label(), pct(err(r, "qdot")));
    for (const auto& sig : r.errors.signals)
      if (sig.name != "qdot") s += fmt::format(" and {} for {}", pct(sig.max_rel), sig.name);
    s += ". ";
  }
  s += fmt::format(
      "Reference: the full model (Simbody, {}) at tolerance {:.0e}; halving that tolerance changed "
      "the speed by {}",
      v.reference_run.integrator == "rkmerson" ? "Runge–Kutta–Merson" : v.reference_run.integrator, v.reference_tolerance,
      pct(v.reference_change.signals[0].max_rel));
  for (size_t k = 1; k < v.reference_change.signals.size(); ++k)
    s += fmt::format(" and {} by {}", v.reference_change.signals[k].name, pct(v.reference_change.signals[k].max_rel));
  s += " of their peaks. Errors are maxima over the steady cycles.";
  return s;
}

nlohmann::json summary_json(const ValidationResult& v) {
  nlohmann::json j;
  j["scene"] = v.scene;
  j["scene_file"] = v.scene_file;
  j["machine"] = v.machine;
  j["duration_s"] = v.duration_s;
  j["output_interval_s"] = v.output_interval_s;
  j["reference"] = {{"integrator", v.reference_run.integrator},
                    {"tolerance", v.reference_tolerance},
                    {"wall_s", v.reference_wall_s},
                    {"stability", run_json(v.reference_run)},
                    {"change_when_tolerance_halved", comparison_json(v.reference_change)}};
  j["steady_window"] = {{"t_start_s", v.window.t_start}, {"revolutions", v.window.revolutions}, {"how", v.window.how}};
  j["extraction_ms"] = v.extraction_ms;
  j["extraction_ms_per_simulated_s"] = v.extraction_ms / v.duration_s;
  nlohmann::json ex = nlohmann::json::array();
  for (const auto& e : v.extractions)
    ex.push_back({{"grid_deg", e.grid_deg}, {"ms", e.ms}, {"kinetostatic_calls", e.calls}, {"points", e.points}});
  j["extractions"] = ex;
  j["headline_quantity"] = v.headline_quantity;
  j["matched_error_target"] = v.matched_target;
  j["speedup_at_matched_error"] = v.speedup_at_matched_error ? nlohmann::json(*v.speedup_at_matched_error) : nullptr;
  if (v.matched_full >= 0) j["matched_full"] = run_json(v.runs[v.matched_full]);
  if (v.matched_reduced >= 0) j["matched_reduced"] = run_json(v.runs[v.matched_reduced]);
  // The settings to use for this scene, chosen from the measurements: the cheapest reduced
  // run within the target on the speed and on the headline quantity.
  const RunRecord* rec = nullptr;
  for (const auto& r : v.runs)
    if (r.model == "reduced" && r.failure.empty() && err(r, "qdot") <= v.matched_target &&
        err(r, v.headline_quantity) <= v.matched_target && (!rec || r.per_simulated_s < rec->per_simulated_s))
      rec = &r;
  j["recommended_reduced"] = rec ? run_json(*rec) : nlohmann::json(nullptr);
  j["headline"] = headline(v);
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : v.runs) runs.push_back(run_json(r));
  j["runs"] = runs;
  if (v.calibration) {
    const auto& c = *v.calibration;
    j["calibration"] = {{"target_cadence_hz", v.calibration_options.cadence_hz},
                        {"target_power_w", v.calibration_options.power_w},
                        {"hip_torque_Nm", c.torque_Nm},
                        {"original_authors_hip_torque_Nm", 69.7},
                        {"mean_cadence_hz_reduced", c.mean_cadence_hz_reduced},
                        {"mean_cadence_hz_full", c.mean_cadence_hz_full},
                        {"mean_power_w", c.mean_power_w},
                        {"peak_force_N", c.peak_force_N},
                        {"speed_fluctuation", c.speed_fluctuation},
                        {"drive_work_per_rev_per_Nm", c.drive_work_per_rev_per_Nm}};
  }
  nlohmann::json th = nlohmann::json::array();
  for (const auto& t : v.thresholds)
    th.push_back({{"quantity", t.threshold.quantity},
                  {"grid_deg", t.threshold.grid_deg},
                  {"max_error", t.threshold.max_error},
                  {"error", t.error},
                  {"pass", t.pass},
                  {"run", t.run}});
  j["thresholds"] = th;
  j["status"] = v.pass ? "pass" : "fail";
  j["failures"] = v.failures;
  return j;
}

void write_validation_report(const ValidationResult& v, const std::string& dir) {
  const std::string Q = v.headline_quantity;
  const double tol = tightest_reduced_tol(v);
  const auto grids = grids_of(v);
  write_text(dir + "/summary.json", summary_json(v).dump(2) + "\n");

  // runs.csv: every run.
  {
    std::string s = "model,label,grid_deg,interpolation,energy_consistent,integrator,tolerance,fixed_step_s,"
                    "wall_s_per_simulated_s,steps,energy_residual_rel,pareto,excluded_samples";
    for (const auto& sig : v.reference_change.signals) s += ",max_rel_" + sig.name + ",rms_rel_" + sig.name;
    s += "\n";
    for (const auto& r : v.runs) {
      s += fmt::format("{},{},{},{},{},{},{:g},{:g},{:.6g},{},{:.3g},{},{}", r.model, csv_field(r.label()), r.grid_deg,
                       r.interpolation, r.energy_consistent ? 1 : 0, r.integrator, r.tolerance, r.fixed_step_s,
                       r.per_simulated_s, r.steps, r.energy_residual_rel, r.pareto ? 1 : 0, r.errors.excluded);
      for (const auto& sig : r.errors.signals) s += fmt::format(",{:.6g},{:.6g}", sig.max_rel, sig.rms_rel);
      s += "\n";
    }
    write_text(dir + "/runs.csv", s);
  }

  // Figure 1: reduced parameters (the paper's Fig. 4).
  const size_t nf = (v.dense_names.size() - 3) / 2;
  {
    std::string s = "q_deg";
    const auto& sm = v.samples10;
    std::vector<int> cols;
    for (size_t c = 1; c < v.dense_names.size(); ++c) {
      s += "," + v.dense_names[c];
      cols.push_back(sm.column(v.dense_names[c]));
    }
    s += "\n";
    for (size_t i = 0; i <= sm.q.size(); ++i) {  // repeat the first point at +360°
      const size_t k = i % sm.q.size();
      s += fmt::format("{:.10g}", (sm.q[k] + (i == sm.q.size() ? 2 * M_PI : 0)) * 180 / M_PI);
      for (int c : cols) s += fmt::format(",{:.10g}", sm.columns[c][k]);
      s += "\n";
    }
    write_text(dir + "/params.csv", s);
    s = fmt::format("{}\n", fmt::join(v.dense_names, ","));
    for (size_t i = 0; i < v.dense_params[0].size(); ++i) {
      for (size_t c = 0; c < v.dense_params.size(); ++c) s += fmt::format("{}{:.10g}", c ? "," : "", v.dense_params[c][i]);
      s += "\n";
    }
    write_text(dir + "/params_dense.csv", s);
    std::string gp = fmt::format(
        "# Reduced parameters vs the independent coordinate. Restyle freely; data: params.csv (10° samples),\n"
        "# params_dense.csv (the interpolant at 1°).\n"
        "set terminal svg size 960,{} dynamic enhanced font 'sans,11' background rgb 'white'\n"
        "set output 'params.svg'\nset datafile separator ','\nset grid\nset key bottom right\n"
        "set xlabel 'q [deg]'\nset xtics 60\nset multiplot layout {},2 title 'Reduced parameters (points: 10° "
        "samples from kinetostatic calls; lines: interpolant)'\n",
        nf ? 640 : 330, nf ? 2 : 1);
    const char* units[] = {"kg·m^2", "kg·m^2"};
    for (size_t c = 1; c < v.dense_names.size(); ++c) {
      const std::string unit = c <= 2 ? units[c - 1] : "kg·m";
      gp += fmt::format(
          "set title {} noenhanced\nplot 'params_dense.csv' skip 1 using 1:{} with lines lw 2 lc rgb '#1f77b4' "
          "title 'interpolant', 'params.csv' skip 1 using 1:{} with points pt 7 ps 0.6 lc rgb '#d62728' title "
          "'samples'\n",
          gnuplot_quoted(v.dense_names[c] + " [" + unit + "]"), c + 1, c + 1);
    }
    gp += "unset multiplot\n";
    write_text(dir + "/params.gp", gp);
  }

  // Figure 2: speed and first constraint force, full vs reduced (the paper's Fig. 5).
  {
    const auto& f = v.reference;
    const auto& r = v.showcase;
    const double t0 = std::max(v.window.t_start, f.t.back() - 3.0);
    std::string s = "t,qdot_full,qdot_reduced,qdot_diff";
    const bool has_f = !f.forces.empty();
    if (has_f) s += fmt::format(",F_{0}_full,F_{0}_reduced,F_{0}_diff", f.force_names[0]);
    s += "\n";
    for (size_t i = 0; i < f.t.size() && i < r.t.size(); ++i) {
      if (f.t[i] < t0) continue;
      s += fmt::format("{:.6f},{:.10g},{:.10g},{:.6g}", f.t[i], f.qdot[i], r.qdot[i], r.qdot[i] - f.qdot[i]);
      if (has_f) s += fmt::format(",{:.10g},{:.10g},{:.6g}", f.forces[0][i], r.forces[0][i], r.forces[0][i] - f.forces[0][i]);
      s += "\n";
    }
    write_text(dir + "/compare.csv", s);
    std::string gp =
        "# Full model vs reduced model (10° table). Data: compare.csv.\n"
        "set terminal svg size 960,640 dynamic enhanced font 'sans,11' background rgb 'white'\n"
        "set output 'timeseries.svg'\nset datafile separator ','\nset grid\nset xlabel 't [s]'\n"
        "set multiplot layout 2,2 title 'Full model (Simbody) and reduced model (10° table), last cycles'\n"
        "set title 'pedal speed [rad/s]'\nplot 'compare.csv' skip 1 using 1:2 with lines lw 3 lc rgb '#aaaaaa' title "
        "'full', '' skip 1 using 1:3 with lines lw 1 lc rgb '#d62728' title 'reduced'\n"
        "set title 'reduced − full [rad/s]'\nplot 'compare.csv' skip 1 using 1:4 with lines lc rgb '#1f77b4' notitle\n";
    if (has_f)
      gp += fmt::format(
          "set title {0} noenhanced\nplot 'compare.csv' skip 1 using 1:5 with lines lw 3 lc rgb '#aaaaaa' "
          "title 'full', '' skip 1 using 1:6 with lines lw 1 lc rgb '#d62728' title 'reduced'\n"
          "set title 'reduced − full [N]'\nplot 'compare.csv' skip 1 using 1:7 with lines lc rgb '#1f77b4' notitle\n",
          gnuplot_quoted(f.force_names[0] + " force [N]"));
    gp += "unset multiplot\n";
    write_text(dir + "/timeseries.gp", gp);
  }

  // Figure 3: error vs computing time, Pareto front, full-model ladder.
  {
    std::string red = "wall_s_per_simulated_s,error,label\n", front = red, full = red;
    std::vector<const RunRecord*> fr;
    for (const auto& r : v.runs) {
      if (!r.failure.empty()) continue;  // stopped runs have no error to plot
      const double e = std::max(err(r, Q), 1e-12);
      const std::string line = fmt::format("{:.6g},{:.6g},{}\n", r.per_simulated_s, e, csv_field(r.label()));
      (r.model == "full" ? full : red) += line;
      if (r.model == "reduced" && r.pareto) fr.push_back(&r);
    }
    std::sort(fr.begin(), fr.end(), [](auto a, auto b) { return a->per_simulated_s < b->per_simulated_s; });
    for (const auto* r : fr) front += fmt::format("{:.6g},{:.6g},{}\n", r->per_simulated_s, std::max(err(*r, Q), 1e-12), csv_field(r->label()));
    write_text(dir + "/pareto_reduced.csv", red);
    write_text(dir + "/pareto_front.csv", front);
    write_text(dir + "/pareto_full.csv", full);
    write_text(dir + "/pareto.gp",
               fmt::format("# Error of the {0} (max over the steady cycles, relative to its peak) against computing time\n"
                           "# per simulated second. Data: pareto_reduced.csv, pareto_front.csv, pareto_full.csv.\n"
                           "set terminal svg size 960,560 dynamic enhanced font 'sans,11' background rgb 'white'\n"
                           "set output 'pareto.svg'\nset datafile separator ','\nset grid\nset logscale xy\n"
                           "set format x '10^{{%L}}'\nset format y '10^{{%L}}'\n"
                           "set xlabel 'computing time per simulated second [s]'\nset ylabel {2} noenhanced\n"
                           "set title 'Accuracy against cost: every reduced run, its Pareto front, and the full-model "
                           "tolerance ladder'\nset key outside right\n"
                           "plot 'pareto_reduced.csv' skip 1 using 1:2 with points pt 6 ps 0.6 lc rgb '#999999' title "
                           "'reduced runs', 'pareto_front.csv' skip 1 using 1:2 with linespoints pt 7 lw 2 lc rgb '#d62728' "
                           "title 'reduced Pareto front', 'pareto_full.csv' skip 1 using 1:2 with linespoints pt 5 lw 2 lc "
                           "rgb '#1f77b4' title 'full model (tolerance ladder)', {1:g} with lines dt 2 lc rgb '#555555' title "
                           "'matched-error target'\n",
                           Q, v.matched_target, gnuplot_quoted(Q + " error / peak")));
  }

  // Figure 4: error vs grid step with the observed order.
  std::vector<std::pair<std::string, double>> orders;
  {
    const double floor = 10 * std::max(1e-12, v.reference_change.find(Q) ? v.reference_change.find(Q)->max_rel : 0.0);
    std::string s = "grid_deg";
    for (const char* i : kInterps) s += std::string(",") + i;
    s += "\n";
    std::vector<std::vector<std::pair<double, double>>> pts(4);
    for (double g : grids) {
      s += fmt::format("{:g}", g);
      for (int k = 0; k < 4; ++k) {
        const auto* r = find_run(v, g, kInterps[k], false, "rk8pd", tol);
        const double e = r ? err(*r, Q) : NAN;
        s += std::isfinite(e) ? fmt::format(",{:.6g}", std::max(e, 1e-12)) : ",";
        if (std::isfinite(e)) pts[k].push_back({g, e});
      }
      s += "\n";
    }
    write_text(dir + "/convergence.csv", s);
    std::string gp =
        "# Error against grid step (rk8pd at the tightest tolerance). Data: convergence.csv.\n"
        "set terminal svg size 960,560 dynamic enhanced font 'sans,11' background rgb 'white'\n"
        "set output 'convergence.svg'\nset datafile separator ','\nset grid\nset logscale xy\nset format y '10^{%L}'\n"
        "set xlabel 'grid step [deg]'\nset ylabel " + gnuplot_quoted(Q + " error / peak") + " noenhanced\nset key outside right\n"
        "set title 'Convergence with the grid (slopes: observed order, fitted above 10× the reference floor)'\n"
        "plot ";
    const char* colors[] = {"#1f77b4", "#2ca02c", "#9467bd", "#d62728"};
    for (int k = 0; k < 4; ++k) {
      const double o = observed_order(pts[k], floor);
      orders.push_back({kInterps[k], o});
      gp += fmt::format("{}'convergence.csv' skip 1 using 1:{} with linespoints pt 7 lw 2 lc rgb '{}' title '{} (order "
                        "{})'",
                        k ? ", " : "", k + 2, colors[k], kInterps[k], std::isfinite(o) ? fmt::format("{:.1f}", o) : "n/a");
    }
    gp += "\n";
    write_text(dir + "/convergence.gp", gp);
  }

  // Render the figures.
  std::string figures_note;
  bool gnuplot_ok = true;
  // No shell: gnuplot gets an argument vector and runs in the report's folder (60 s each).
  for (const char* name : {"params", "timeseries", "pareto", "convergence"}) {
    const auto run = run_program({"gnuplot", std::string(name) + ".gp"}, dir, dir + "/gnuplot.log", 60.0);
    if (!run.ok()) gnuplot_ok = false;
  }
  auto svg = [&](const std::string& name) {
    std::string text = read_text(dir + "/" + name + ".svg");
    const auto at = text.find("<svg");
    if (at == std::string::npos) return fmt::format("<p class=warn>Figure {}.svg could not be rendered (see gnuplot.log).</p>", name);
    return text.substr(at);
  };
  if (!gnuplot_ok) figures_note = "<p class=warn>gnuplot reported errors; see gnuplot.log beside this report.</p>";

  // report.html
  std::string h;
  h += "<!DOCTYPE html><html lang=en><head><meta charset='utf-8'><title>rdyn validation: " + H(v.scene) + "</title>";
  h += "<style>body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;line-height:1.45;color:#222}"
       "h1{font-size:1.6em}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ccc}"
       "table{border-collapse:collapse;font-size:.85em}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}"
       "th{background:#f3f3f3}td.l{text-align:left}.lead{font-size:1.08em;background:#f6f9ff;padding:.8em;border-left:"
       "4px solid #1f77b4}.warn{color:#a00}.pass{color:#070;font-weight:bold}.fail{color:#a00;font-weight:bold}"
       "svg{max-width:100%;height:auto}code{background:#f3f3f3;padding:0 3px}</style></head><body>";
  h += "<h1>rdyn validation: " + H(v.scene) + "</h1>";
  h += "<p class=lead>" + H(headline(v)) + "</p>";
  if (!v.failures.empty()) {
    h += "<p class=fail>Validation FAILED:</p><ul>";
    for (const auto& f : v.failures) h += "<li class=warn>" + H(f) + "</li>";
    h += "</ul>";
  }
  if (!v.note.empty()) h += "<p><b>What this scene tests:</b> " + H(v.note) + "</p>";
  h += fmt::format("<p>Scene file: <code>{}</code>. Simulated {:g} s, output every {:g} s. Steady cycles: {}. "
                   "Samples lying between the two models' instants of a load switch (where the force jumps) are "
                   "excluded from the error maxima and counted in <code>runs.csv</code>.</p>",
                   H(v.scene_file), v.duration_s, v.output_interval_s, H(v.window.how));
  h += figures_note;
  h += "<h2>1. Reduced parameters</h2><p>m1, m2 of Eksergian's equation <code>m1 q̈ + m2 q̇² = F*</code> and me1, me2 of "
       "each constraint line <code>me1 q̈ + me2 q̇² = F_E + Q_x</code>, from kinetostatic calls of the full model at 10° "
       "(the paper's Fig. 4).</p>" + svg("params");
  h += "<h2>2. Full and reduced model over the last cycles</h2><p>The paper's Fig. 5, with the difference.</p>" + svg("timeseries");
  h += "<h2>3. Accuracy against computing time</h2>" + svg("pareto");
  h += "<h2>4. Convergence with the grid</h2>" + svg("convergence");
  h += "<p>Observed orders:";
  for (const auto& [name, o] : orders) h += fmt::format(" {} {};", name, std::isfinite(o) ? fmt::format("{:.2f}", o) : "n/a");
  h += " The trigonometric (<code>fourier</code>) interpolant of the same samples converges spectrally for these "
       "smooth periodic parameters until it reaches the full model's own accuracy; the cubic spline (the original "
       "authors' choice) at fourth order.</p>";
  if (v.calibration) {
    const auto& c = *v.calibration;
    h += "<h2>5. Calibration against the original authors</h2>";
    h += fmt::format(
        "<p>With the resistance dissipating {:g} W at {:g} Hz, the hip torque that holds a mean steady cadence of {:g} "
        "Hz is <b>{:.2f} N·m</b> (reduced model: {:.6f} Hz; confirmed with the full model: {:.6f} Hz). The original "
        "authors found 69.7 N·m by hand. Mean power {:.2f} W, speed fluctuation {:.3g} %, peak {} force {:.0f} N.</p>",
        v.calibration_options.power_w, v.calibration_options.cadence_hz, v.calibration_options.cadence_hz, c.torque_Nm,
        c.mean_cadence_hz_reduced, c.mean_cadence_hz_full, c.mean_power_w, 100 * c.speed_fluctuation, c.force_name,
        c.peak_force_N);
    h += fmt::format(
        "<p><b>Why the torques differ.</b> At steady state the hip torques' work per revolution equals the dissipated "
        "energy, and a torque applied only while a thigh descends does work T·Δθ per leg, where Δθ is that thigh's "
        "descending swing. Here the two thighs together sweep {:.3f} rad per revolution ({:.1f}° each), so "
        "{:.2f} N·m × {:.3f} rad = {:.1f} J = {:g} W / {:g} Hz. The original authors' 69.7 N·m implies {:.3f} rad "
        "({:.1f}° per thigh). The difference comes from the leg geometry: our segment lengths and masses are de Leva's "
        "(1996) scaled to a {}-subject, with the saddle set for 30° knee flexion at full extension, while the authors "
        "measured their subject's segments (not available to us); the thigh swing — hence the torque — depends on "
        "thigh, shank and crank lengths and the hip position. Two legs are modelled (one leg would need a thigh swing of "
        "{:.0f}°, which no leg on a bicycle reaches), and the resistance law (viscous here) only changes the torque "
        "through the {:.2g} % speed fluctuation.</p>",
        c.drive_work_per_rev_per_Nm, c.drive_work_per_rev_per_Nm / 2 * 180 / M_PI, c.torque_Nm,
        c.drive_work_per_rev_per_Nm, c.torque_Nm * c.drive_work_per_rev_per_Nm, v.calibration_options.power_w,
        v.calibration_options.cadence_hz, v.calibration_options.power_w / v.calibration_options.cadence_hz / 69.7,
        v.calibration_options.power_w / v.calibration_options.cadence_hz / 69.7 / 2 * 180 / M_PI, "reference",
        v.calibration_options.power_w / v.calibration_options.cadence_hz / 69.7 * 180 / M_PI, 100 * c.speed_fluctuation);
  }
  if (!v.thresholds.empty()) {
    h += "<h2>Acceptance thresholds</h2><table><tr><th>quantity</th><th>grid</th><th>limit</th><th>error</th><th>run</th><th></th></tr>";
    for (const auto& t : v.thresholds)
      h += fmt::format("<tr><td class=l>{}</td><td>{:g}°</td><td>{}</td><td>{}</td><td class=l>{}</td><td class={}>{}</td></tr>",
                       H(t.threshold.quantity), t.threshold.grid_deg, pct(t.threshold.max_error), pct(t.error), H(t.run),
                       t.pass ? "pass" : "fail", t.pass ? "pass" : "FAIL");
    h += "</table>";
  }
  h += "<h2>All runs</h2><p>Median wall time of repeated runs per simulated second; errors are maxima over the steady "
       "cycles relative to the reference's peak (RMS in <code>runs.csv</code>). ★: on the Pareto front of its model.</p>"
       "<table><tr><th>run</th><th>time / sim. s</th><th>steps</th><th>energy residual</th>";
  for (const auto& sig : v.reference_change.signals) h += "<th>" + H(sig.name) + "</th>";
  h += "</tr>";
  for (const auto& r : v.runs) {
    if (!r.failure.empty()) {
      h += fmt::format("<tr><td class=l>{}</td><td class=l colspan={}>stopped: {}</td></tr>", H(r.label()),
                       3 + v.reference_change.signals.size(), H(r.failure));
      continue;
    }
    h += fmt::format("<tr><td class=l>{}{}</td><td>{}</td><td>{}</td><td>{:.1e}</td>", r.pareto ? "★ " : "", H(r.label()),
                     secs(r.per_simulated_s), r.steps, r.energy_residual_rel);
    for (const auto& sig : r.errors.signals) h += fmt::format("<td>{:.2e}</td>", sig.max_rel);
    h += "</tr>";
  }
  h += "</table><h2>Extraction cost</h2><table><tr><th>grid</th><th>points</th><th>kinetostatic calls</th><th>time</th></tr>";
  for (const auto& e : v.extractions)
    h += fmt::format("<tr><td>{:g}°</td><td>{}</td><td>{}</td><td>{:.3g} ms</td></tr>", e.grid_deg, e.points, e.calls, e.ms);
  h += fmt::format("</table><p>Amortised over the {:g} s simulated here, the 10° extraction adds {} per simulated "
                   "second.</p>",
                   v.duration_s, secs(v.extraction_ms * 1e-3 / v.duration_s));
  h += "<h2>Files</h2><p><code>summary.json</code> (every number above), <code>runs.csv</code>, and for each figure its "
       "data (<code>*.csv</code>) and gnuplot script (<code>*.gp</code>): edit a script and run <code>gnuplot NAME.gp</code> "
       "in this folder to restyle it.</p><p>Machine: " + H(v.machine) + ".</p></body></html>\n";
  write_text(dir + "/report.html", h);
}

}  // namespace rdyn::validate
