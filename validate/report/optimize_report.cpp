#include "validate/report/optimize_report.hpp"
#include "validate/report/cycle_animation.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "validate/io/escape.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/io/run_program.hpp"

namespace rdyn::validate {

using json = nlohmann::json;

namespace {

json strategy_json(const StrategyResult& s) {
  json loads = json::array();
  for (size_t i = 0; i < s.a0.size(); ++i) loads.push_back({{"a0", s.a0[i]}, {"a", s.a[i]}, {"b", s.b[i]}});
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"amplitude", s.amplitude},
          {"resistance_coefficient", num(s.resistance_coefficient)},
          {"peak_force_reduced_N", s.peak_reduced_N},
          {"peak_force_full_N", num(s.peak_full_N)},
          {"objective_reduced", s.objective_reduced},
          {"mean_cadence_hz_reduced", s.cadence_reduced_hz},
          {"mean_cadence_hz_full", num(s.cadence_full_hz)},
          {"mean_power_w", s.mean_power_w},
          {"max_load", s.max_torque_Nm},
          {"steady_q", s.steady_q},
          {"steady_qdot", s.steady_qdot},
          {"coefficients", loads}};
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string H(const std::string& s) { return html_escape(s); }

std::string svg_or_note(const std::map<std::string, std::string>& figures, const std::string& name) {
  const auto it = figures.find(name);
  const auto at = it == figures.end() ? std::string::npos : it->second.find("<svg");
  if (at == std::string::npos)
    return fmt::format("<p class=warn>Figure {}.svg could not be rendered (see gnuplot.log).</p>", name);
  return it->second.substr(at);
}

// Two panels over the angle: the design loads' applied torque, and the force, constant vs
// optimised, reduced (lines) and full (points).
std::string figure_gp(const json& s, bool torques) {
  const auto& loads = s.at("design_loads");
  const std::string force = s.at("force_name").get<std::string>();
  std::string gp =
      "set terminal svg size 960,420 dynamic noenhanced font 'sans,11' background rgb 'white'\n"
      "set datafile separator ','\nset grid\nset key outside right\nset xrange [0:360]\nset xtics 45\n";
  gp += fmt::format("set output '{}'\nset xlabel {}\n", torques ? "torques.svg" : "force.svg",
                    gnuplot_quoted(s.at("independent").get<std::string>() + " angle [deg]"));
  if (torques) {
    gp += "set ylabel " + gnuplot_quoted("applied load (gated) [N·m or N]") + "\nplot ";
    for (size_t l = 0; l < loads.size(); ++l) {
      const std::string n = loads[l].get<std::string>();
      gp += fmt::format("{}'profile.csv' using 1:{} with lines dt 2 lw 1.5 title {}, 'profile.csv' using 1:{} with "
                        "lines lw 2 title {}",
                        l ? ", " : "", 2 + 2 * l, gnuplot_quoted(n + " constant"), 3 + 2 * l,
                        gnuplot_quoted(n + " optimised"));
    }
  } else {
    const size_t c = 2 + 2 * loads.size();
    gp += "set ylabel " + gnuplot_quoted(force + " force [N]") + "\n";
    gp += fmt::format(
        "plot 'profile.csv' using 1:{} with lines dt 2 lw 1.5 title 'constant, reduced', 'profile.csv' using 1:{} "
        "with lines lw 2 title 'optimised, reduced', 'profile.csv' using 1:{} every 5 with points pt 6 ps 0.5 title "
        "'constant, full (Simbody)', 'profile.csv' using 1:{} every 5 with points pt 7 ps 0.5 title 'optimised, full "
        "(Simbody)'\n",
        c, c + 1, c + 2, c + 3);
  }
  if (torques) gp += "\n";
  return gp;
}

}  // namespace

json optimize_summary(const OptimizeResult& r) {
  json loads = json::array();
  for (size_t i = 0; i < r.design_loads.size(); ++i)
    loads.push_back({{"load", r.design_loads[i]},
                     {"same_as", r.same_as[i].empty() ? json(nullptr) : json(r.same_as[i])},
                     {"shift_deg", r.shift_deg[i]}});
  // A value that is missing or not finite is null (an empty CSV field), never NaN.
  const size_t n = r.constant.curves.angle_deg.size();
  auto nums = [n](const std::vector<double>& v) {
    json a = json::array();
    for (size_t i = 0; i < n; ++i) a.push_back(i < v.size() && std::isfinite(v[i]) ? json(v[i]) : json(nullptr));
    return a;
  };
  json curves = {{"angle_deg", r.constant.curves.angle_deg}};
  for (size_t l = 0; l < r.design_loads.size(); ++l) {
    curves[r.design_loads[l] + "_constant"] = nums(r.constant.curves.torque_Nm[l]);
    curves[r.design_loads[l] + "_optimised"] = nums(r.optimised.curves.torque_Nm[l]);
  }
  curves["force_constant_reduced"] = nums(r.constant.curves.force_reduced_N);
  curves["force_optimised_reduced"] = nums(r.optimised.curves.force_reduced_N);
  curves["force_constant_full"] = nums(r.constant.curves.force_full_N);
  curves["force_optimised_full"] = nums(r.optimised.curves.force_full_N);
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"scene", r.scene},
          {"status", optimize_failure_message(r).empty() ? "pass" : "fail"},
          {"force_name", r.force_name},
          {"objective", r.objective},
          {"p", r.objective == "pnorm" ? json(r.p) : json(nullptr)},
          {"harmonics", r.harmonics},
          {"independent", r.independent},
          {"full_duration_s", r.full_duration_s},
          {"profile_of", r.profile_of},
          {"target_cadence_hz", r.cadence_hz},
          {"target_power_w", r.power_w > 0 ? json(r.power_w) : json(nullptr)},
          {"resistance_coefficient", num(r.resistance_coefficient)},
          {"max_load", r.max_load},
          {"design_loads", r.design_loads},
          {"design", loads},
          {"added_loads", r.added_loads},
          {"constant", strategy_json(r.constant)},
          {"optimised", strategy_json(r.optimised)},
          {"peak_reduction_reduced", r.reduction_reduced},
          {"peak_reduction_full", num(r.reduction_full)},
          {"reduced_full_agreement", num(r.agreement)},
          {"optimiser", r.optimiser},
          {"evaluations", r.evaluations},
          {"failed_evaluations", r.failed_evaluations},
          {"stop_reason", r.stop_reason},
          {"optimise_wall_time_s", r.optimise_wall_s},
          {"wall_time_s", r.wall_time_s},
          {"curves", curves}};
}

std::string optimize_profile_csv(const json& s) {
  const auto& c = s.at("curves");
  const auto& loads = s.at("design_loads");
  const std::string f = s.at("force_name").get<std::string>();
  std::vector<std::string> cols;
  for (const auto& l : loads) cols.push_back(l.get<std::string>() + "_constant"), cols.push_back(l.get<std::string>() + "_optimised");
  std::string out = "q_deg";
  for (const auto& n : cols) out += "," + csv_field(n);
  const std::vector<std::string> fcols = {"force_constant_reduced", "force_optimised_reduced", "force_constant_full",
                                          "force_optimised_full"};
  for (const auto& n : {"constant_reduced", "optimised_reduced", "constant_full", "optimised_full"})
    out += "," + csv_field("F_" + f + "_" + n);
  out += "\n";
  const auto& angle = c.at("angle_deg");
  for (size_t i = 0; i < angle.size(); ++i) {
    out += fmt::format("{:g}", angle[i].get<double>());
    std::vector<std::string> all = cols;
    all.insert(all.end(), fcols.begin(), fcols.end());
    for (const auto& n : all) {
      const auto& v = c.at(n)[i];
      out += v.is_number() ? fmt::format(",{:.10g}", v.get<double>()) : std::string(",");
    }
    out += "\n";
  }
  return out;
}

std::string render_optimize_html(const json& s, const std::map<std::string, std::string>& figures) {
  auto d = [&](const json& j, const char* k) { return j.at(k).is_number() ? j.at(k).get<double>() : NAN; };
  const json& c = s.at("constant");
  const json& o = s.at("optimised");
  const std::string f = s.at("force_name").get<std::string>();
  const bool pass = s.at("status") == "pass";
  std::string h =
      "<!DOCTYPE html><html lang=en><head><meta charset='utf-8'><title>rdyn optimize: " + H(s.at("scene")) +
      "</title><style>body{font-family:sans-serif;max-width:1000px;margin:2em auto;padding:0 1em;line-height:1.45;"
      "color:#222}h2{font-size:1.25em;margin-top:2em;border-bottom:1px solid #ccc}table{border-collapse:collapse;"
      "font-size:.9em}td,th{border:1px solid #ccc;padding:2px 6px;text-align:right}th{background:#f3f3f3}"
      "td.l{text-align:left}.pass{color:#070;font-weight:bold}.fail{color:#a00;font-weight:bold}.warn{color:#a00}"
      "svg{max-width:100%;height:auto}.lead{background:#f6f9ff;padding:.8em;border-left:4px solid #1f77b4}"
      "</style></head><body>";
  h += "<h1>rdyn optimize: " + H(s.at("scene")) + " — <span class=" + (pass ? "pass>pass" : "fail>FAIL") +
       "</span></h1>";
  h += fmt::format(
      "<p class=lead>Peak {} force over the steady cycle: {:.1f} N with the constant strategy, {:.1f} N optimised "
      "on the full model (Simbody, {:g} s runs): {:.1f} % lower ({:.1f} % on the reduced model). Both hold a mean "
      "cadence of {:g} Hz (full model: {:.4f} / {:.4f} Hz).</p>",
      H(f), d(c, "peak_force_full_N"), d(o, "peak_force_full_N"), d(s, "full_duration_s"), 100 * d(s, "peak_reduction_full"),
      100 * d(s, "peak_reduction_reduced"), d(s, "target_cadence_hz"), d(c, "mean_cadence_hz_full"),
      d(o, "mean_cadence_hz_full"));
  h += "<table><tr><th></th><th>constant</th><th>optimised</th></tr>";
  auto row = [&](const std::string& name, const char* key, const char* spec) {
    h += "<tr><td class=l>" + H(name) + "</td><td>" + fmt::format(fmt::runtime(spec), d(c, key)) + "</td><td>" +
         fmt::format(fmt::runtime(spec), d(o, key)) + "</td></tr>";
  };
  row("amplitude [N·m or N]", "amplitude", "{:.4f}");
  row("peak " + f + " force, reduced [N]", "peak_force_reduced_N", "{:.2f}");
  row("peak " + f + " force, full [N]", "peak_force_full_N", "{:.2f}");
  row("mean cadence, reduced [Hz]", "mean_cadence_hz_reduced", "{:.6f}");
  row("mean cadence, full [Hz]", "mean_cadence_hz_full", "{:.6f}");
  row("mean drive power, reduced [W]", "mean_power_w", "{:.3f}");
  row("largest |value·τ(θ)| [N·m or N]", "max_load", "{:.2f}");
  h += "</table>";
  h += fmt::format("<p>{} evaluations of the reduced steady cycle ({} failed) by {} in {:.2f} s (stop: {}); whole run "
                   "{:.1f} s. Objective: {}{}. Reduced vs full peak at the optimum: {:.2g} relative.</p>",
                   s.at("evaluations").get<int>(), s.at("failed_evaluations").get<int>(), H(s.at("optimiser")),
                   d(s, "optimise_wall_time_s"), H(s.at("stop_reason")), d(s, "wall_time_s"), H(s.at("objective")),
                   s.at("p").is_number() ? fmt::format(" (p = {:g})", s.at("p").get<double>()) : std::string(),
                   d(s, "reduced_full_agreement"));
  h += mechanism_drawing_html(s) + strategies_animation_html(s);  // validate/report/cycle_animation.hpp
  h += "<h2>1. Drive loads over the angle</h2>" + svg_or_note(figures, "torques");
  h += "<h2>2. " + H(f) + " force over the angle</h2>" + svg_or_note(figures, "force");
  h += "<h2>3. Shapes</h2><table><tr><th>load</th><th>same as</th><th>shift [deg]</th><th>a0</th><th>a_k</th>"
       "<th>b_k</th></tr>";
  const auto& design = s.at("design");
  for (size_t i = 0; i < design.size(); ++i) {
    const auto& co = o.at("coefficients")[i];
    std::string a, b;
    for (const auto& v : co.at("a")) a += fmt::format("{}{:.4f}", a.empty() ? "" : ", ", v.get<double>());
    for (const auto& v : co.at("b")) b += fmt::format("{}{:.4f}", b.empty() ? "" : ", ", v.get<double>());
    h += "<tr><td class=l>" + H(design[i].at("load")) + "</td><td class=l>" +
         (design[i].at("same_as").is_string() ? H(design[i].at("same_as")) : std::string("—")) + "</td><td>" +
         fmt::format("{:g}", design[i].at("shift_deg").get<double>()) + "</td><td>" +
         fmt::format("{:.4f}", co.at("a0").get<double>()) + "</td><td class=l>" + a + "</td><td class=l>" + b +
         "</td></tr>";
  }
  h += "</table><p>τ(θ) = a0 + Σ a_k cos kθ + b_k sin kθ of the angle of <code>" + H(s.at("profile_of")) +
       "</code>; the applied load is the amplitude times τ, while its rate gate is on. The force is a rigid-body "
       "joint reaction along the requested direction, not a muscle-level joint load (docs/theory.md).</p>";
  h += "</body></html>\n";
  return h;
}

void render_optimize_report(const json& s, const std::string& dir) {
  write_text_file(dir + "/summary.json", s.dump(2) + "\n");
  write_text_file(dir + "/profile.csv", optimize_profile_csv(s));
  write_text_file(dir + "/torques.gp", figure_gp(s, true));
  write_text_file(dir + "/force.gp", figure_gp(s, false));
  std::map<std::string, std::string> figures;
  bool ok = true;
  for (const std::string name : {"torques", "force"}) {
    const auto run = run_program({"gnuplot", name + ".gp"}, dir, dir + "/gnuplot.log", 60.0);
    ok &= run.ok();
    figures[name] = read_text(dir + "/" + name + ".svg");
  }
  std::string html = render_optimize_html(s, figures);
  if (!ok) {
    const auto at = html.find("<h2>1.");
    html.insert(at == std::string::npos ? 0 : at,
                "<p class=warn>gnuplot reported errors; see gnuplot.log beside this report.</p>");
  }
  write_text_file(dir + "/report.html", html);
}

}  // namespace rdyn::validate
