#include "validate/harness/summary.hpp"

#include <cmath>

#include "validate/harness/time_scale.hpp"

namespace rdyn::validate {

namespace {

// JSON has no NaN or infinity: they are written as null ("not measured").
nlohmann::json num(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json comparison_json(const Comparison& c) {
  nlohmann::json j = nlohmann::json::object();
  for (const auto& s : c.signals)
    j[s.name] = {{"max_rel", num(s.max_rel)}, {"rms_rel", num(s.rms_rel)}, {"peak", num(s.peak)}};
  return {{"errors", j}, {"samples", c.samples}, {"excluded_between_switches", c.excluded}};
}

// Column-wise table: {"names": [...], "rows": [[...], ...]}.
nlohmann::json table_json(const std::vector<std::string>& names,
                          const std::vector<std::vector<double>>& cols) {
  nlohmann::json rows = nlohmann::json::array();
  const size_t n = cols.empty() ? 0 : cols[0].size();
  for (size_t i = 0; i < n; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (const auto& c : cols) row.push_back(num(c[i]));
    rows.push_back(row);
  }
  return {{"names", names}, {"rows", rows}};
}

// The data of the three data figures: reduced parameters (samples and interpolant) and the
// full and default reduced runs over the last three periods of the scene's time scale.
nlohmann::json figures_json(const ValidationResult& v) {
  nlohmann::json f;
  const auto& sm = v.samples10;
  if (!sm.q.empty() && !v.dense_names.empty()) {
    std::vector<std::vector<double>> cols(v.dense_names.size());
    // A periodic table repeats its first point at +360°; a range table ends at its last point.
    for (size_t i = 0; i < sm.q.size() + (sm.periodic ? 1 : 0); ++i) {
      const size_t k = i % sm.q.size();
      cols[0].push_back((sm.q[k] + (i == sm.q.size() ? 2 * M_PI : 0)) * (sm.revolute ? 180 / M_PI : 1.0));
      for (size_t c = 1; c < v.dense_names.size(); ++c)
        cols[c].push_back(sm.columns[sm.column(v.dense_names[c])][k]);
    }
    f["params_samples"] = table_json(v.dense_names, cols);
    f["params_dense"] = table_json(v.dense_names, v.dense_params);
  }
  const auto& a = v.reference;
  const auto& b = v.showcase;
  if (!a.t.empty() && b.t.size() == a.t.size()) {
    const double t0 = std::max(v.window.t_start, a.t.back() - 3 * v.time_scale.period_s);
    std::vector<std::string> names{"t", "qdot_full", "qdot_reduced"};
    const bool has_f = !a.forces.empty();
    if (has_f) names.insert(names.end(), {"F_full", "F_reduced"});
    std::vector<std::vector<double>> cols(names.size());
    for (size_t i = 0; i < a.t.size(); ++i) {
      if (a.t[i] < t0) continue;
      cols[0].push_back(a.t[i]);
      cols[1].push_back(a.qdot[i]);
      cols[2].push_back(b.qdot[i]);
      if (has_f) cols[3].push_back(a.forces[0][i]), cols[4].push_back(b.forces[0][i]);
    }
    f["timeseries"] = table_json(names, cols);
    f["timeseries"]["force_name"] = has_f ? a.force_names[0] : "";
    f["timeseries"]["reduced_run"] = v.showcase_run >= 0 ? v.runs[v.showcase_run].label() : "";
    // The requested reactions and shaking load over the same periods: <column>_full, and
    // <column>_reduced where the reduced model gives it (the others are the full model's alone).
    std::vector<std::string> jn{"t"};
    std::vector<const std::vector<double>*> src;
    for (size_t c = 0; c < a.column_names.size(); ++c) {
      const std::string& n = a.column_names[c];
      if (n.rfind("R_", 0) != 0 && n.rfind("shaking_", 0) != 0) continue;
      jn.push_back(n + "_full");
      src.push_back(&a.columns[c]);
      for (size_t d = 0; d < b.column_names.size(); ++d)
        if (b.column_names[d] == n) jn.push_back(n + "_reduced"), src.push_back(&b.columns[d]);
    }
    if (!src.empty()) {
      std::vector<std::vector<double>> jc(jn.size());
      for (size_t i = 0; i < a.t.size(); ++i) {
        if (a.t[i] < t0) continue;
        jc[0].push_back(a.t[i]);
        for (size_t k = 0; k < src.size(); ++k) jc[k + 1].push_back((*src[k])[i]);
      }
      f["joint_outputs"] = table_json(jn, jc);
    }
  }
  return f;
}

// The drive over one revolution from both models (validate/report/drive_figure.hpp draws it):
// each model's RMS, peak and mean [N·m], mean and peak power [W], their differences, and the
// curve on the 1° rows.
nlohmann::json drive_cycle_json(const DriveCycleComparison& c) {
  auto stats = [](const DriveStats& st, double wall_s) {
    return nlohmann::json{{"rms_Nm", num(st.rms)},           {"peak_Nm", num(st.peak)},
                          {"mean_Nm", num(st.mean)},         {"mean_power_W", num(st.mean_power_W)},
                          {"peak_power_W", num(st.peak_power_W)}, {"wall_s", num(wall_s)}};
  };
  std::vector<std::vector<double>> cols(4);
  for (size_t i = 0; i < c.full.t.size(); ++i) {
    cols[0].push_back(c.full.q[i] * 180 / M_PI);
    cols[1].push_back(c.full.t[i]);
    cols[2].push_back(c.full.drive[i]);
    cols[3].push_back(c.reduced.drive[i]);
  }
  const double peak = c.full_stats.peak;
  return {{"cadence_hz", num(c.cadence_hz)},
          {"q0_deg", num(c.q0 * 180 / M_PI)},
          {"unit", "N·m"},
          {"rows", c.full.t.size()},
          {"full", stats(c.full_stats, c.full.wall_s)},
          {"reduced", stats(c.reduced_stats, c.reduced.wall_s)},
          {"peak_difference_Nm", num(c.reduced_stats.peak - c.full_stats.peak)},
          {"rms_difference_Nm", num(c.reduced_stats.rms - c.full_stats.rms)},
          {"mean_power_difference_W", num(c.reduced_stats.mean_power_W - c.full_stats.mean_power_W)},
          {"max_abs_difference_Nm", num(c.max_difference)},
          {"max_abs_difference_rel_peak", num(peak > 0 ? c.max_difference / peak : NAN)},
          {"rms_of_difference_Nm", num(c.rms_difference)},
          {"grid_deg", num(c.grid_deg)},
          {"curve", table_json({"q_deg", "t", "drive_full_Nm", "drive_reduced_Nm"}, cols)}};
}

// Both models at the calibrated operating point (validate/report/calibrated_figure.hpp draws
// it): their differences and the curves on the output rows.
nlohmann::json calibrated_run_json(const CalibratedRun& c) {
  const bool force = !c.force_name.empty();
  std::vector<std::string> names = {"t", "qdot_full", "qdot_reduced"};
  if (force) names.insert(names.end(), {"force_full_N", "force_reduced_N"});
  std::vector<std::vector<double>> cols(names.size());
  const size_t n = std::min(c.full.t.size(), c.reduced.t.size());
  for (size_t i = 0; i < n; ++i) {
    cols[0].push_back(c.full.t[i]);
    cols[1].push_back(c.full.qdot[i]);
    cols[2].push_back(c.reduced.qdot[i]);
    if (force) {
      cols[3].push_back(c.full.forces[0][i]);
      cols[4].push_back(c.reduced.forces[0][i]);
    }
  }
  return {{"cadence_hz", num(c.cadence_hz)},
          {"grid_deg", num(c.grid_deg)},
          {"force_name", c.force_name},
          {"qdot_error", num(c.qdot_error)},
          {"force_error", force ? num(c.force_error) : nlohmann::json(nullptr)},
          {"mean_cadence_full_hz", num(c.mean_cadence_full_hz)},
          {"mean_cadence_reduced_hz", num(c.mean_cadence_reduced_hz)},
          {"curve", table_json(names, cols)}};
}

// The calibration result under neutral names (kCompareQuantities), with what the scene
// compares it to.
nlohmann::json calibration_json(const ValidationResult& v) {
  const auto& c = *v.calibration;
  const double power = v.calibration_options.power_w;
  nlohmann::json j = {{"target_cadence_hz", v.calibration_options.cadence_hz},
                      {"target_power_w", power > 0 ? num(power) : nlohmann::json(nullptr)},
                      {"load", c.load},
                      {"load_kind", c.load_kind},
                      {"load_value", num(c.load_value)},
                      {"load_unit", c.load_unit},
                      {"drive_torque_Nm", num(c.torque_Nm)},  // null unless joint torques (N·m)
                      {"work_per_rev_per_unit", num(c.work_per_rev_per_unit)},
                      {"mean_cadence_hz_reduced", num(c.mean_cadence_hz_reduced)},
                      {"mean_cadence_hz_full", num(c.mean_cadence_hz_full)},
                      {"mean_power_W", num(c.mean_power_w)},
                      {"force_name", c.force_name},
                      {"peak_force_N", num(c.peak_force_N)},
                      {"speed_fluctuation", num(c.speed_fluctuation)},
                      {"drive_work_per_rev_per_Nm",
                       std::isfinite(c.torque_Nm) ? num(c.work_per_rev_per_unit) : nlohmann::json(nullptr)}};
  nlohmann::json cmp = nlohmann::json::array();
  for (const auto& cv : v.compare)
    cmp.push_back({{"quantity", cv.quantity},
                   {"value", cv.value},
                   {"unit", cv.unit},
                   {"source", cv.source},
                   {"explanation", cv.explanation},
                   {"rdyn_value", j.value(cv.quantity, nlohmann::json(nullptr))}});
  j["compare"] = cmp;
  return j;
}

}  // namespace

nlohmann::json run_json(const RunRecord& r) {
  nlohmann::json j = {{"label", r.label()},
                      {"model", r.model},
                      {"integrator", r.integrator},
                      {"tolerance", r.tolerance},
                      {"wall_s", num(r.wall_s)},
                      {"wall_s_per_simulated_s", num(r.per_simulated_s)},
                      {"repeats", r.repeats},
                      {"steps", r.steps},
                      {"rejected_steps", r.rejected},
                      {"smallest_step_s", num(r.smallest_step_s)},
                      {"events", r.events},
                      {"energy_balance_residual_rel", num(r.energy_residual_rel)},
                      {"cycles", num(r.cycles)},
                      {"energy_drift_per_cycle_J", num(r.energy_drift_per_cycle_J)},
                      {"pareto", r.pareto}};
  if (!r.failure.empty()) j["failure"] = r.failure;
  if (r.model == "full") j["constraint_violation_m"] = num(r.constraint_violation_m);
  if (r.timed_output_interval_s > 0) j["timed_output_interval_s"] = r.timed_output_interval_s;
  if (r.model == "full" || r.failure.empty()) j["timed_steps"] = r.timed_steps;
  if (r.model != "full" && r.model != "reduced") {  // a peer engine's fixed-step run
    j["fixed_step_s"] = r.fixed_step_s;
    j["constraint_violation_m"] = num(r.constraint_violation_m);
  }
  if (r.model == "reduced") {
    j["grid_deg"] = r.grid_deg;
    j["interpolation"] = r.interpolation;
    if (!r.fit.empty()) j["fit"] = r.fit;  // the interpolant built (differs from the request on range tables)
    j["energy_consistent_m2"] = r.energy_consistent;
    if (r.integrator == "rk4-fixed") j["fixed_step_s"] = r.fixed_step_s;
    nlohmann::json oi = nlohmann::json::object();
    for (const auto& e : r.output_interpolation.signals) oi[e.name] = num(e.max_rel);
    j["output_interpolation_max_rel"] = oi;  // Hermite rows on the output grid vs the compared rows
    j["compared_run_wall_s"] = num(r.compared_run_wall_s);
  }
  j.update(comparison_json(r.errors));
  return j;
}

namespace {

// The first screen's records (validate/report/first_screen.hpp): the recommended run's one
// comparison, its verdicts and baselines.
void add_first_screen_json(const ValidationResult& v, nlohmann::json& j) {
  // The first screen's one comparison: the recommended run against the cheapest full run at
  // equal or better error, else the ladder's most accurate run (null: no completed full run, the
  // reference stands in; see baselines).
  j["recommended_full"] =
      v.recommended_full >= 0 ? run_json(v.runs[v.recommended_full]) : nlohmann::json(nullptr);
  // false: no ladder run was as accurate; recommended_full is the most accurate one and
  // recommended_speedup a floor ("at least").
  j["recommended_full_as_accurate"] =
      v.recommended_full >= 0 ? nlohmann::json(v.recommended_full_as_accurate) : nlohmann::json(nullptr);
  j["recommended_speedup"] = v.recommended_speedup ? num(*v.recommended_speedup) : nullptr;
  nlohmann::json verdicts = nlohmann::json::array();
  for (const auto& d : v.verdicts)
    verdicts.push_back({{"quantity", d.quantity},
                        {"error", num(d.error)},
                        {"target", num(d.target)},
                        {"within_target", d.within_target}});
  j["verdicts"] = verdicts;
  nlohmann::json baselines = nlohmann::json::array();
  for (const auto& b : v.baselines)
    baselines.push_back({{"what", b.what},
                         {"label", b.label},
                         {"wall_s", num(b.wall_s)},
                         {"speedup", num(b.speedup)}});
  j["baselines"] = baselines;
}

}  // namespace

nlohmann::json summary_json(const ValidationResult& v) {
  nlohmann::json j;
  j["scene"] = v.scene;
  j["scene_file"] = v.scene_file;
  j["note"] = v.note;
  j["machine"] = v.machine;
  j["duration_s"] = v.duration_s;
  j["output_interval_s"] = v.output_interval_s;
  j["time_scale"] = {{"period_s", num(v.time_scale.period_s)}, {"how", v.time_scale.how}};
  j["fixed_steps_s"] = v.fixed_steps;
  // Costs per simulated second only when at least a second was simulated (no extrapolation).
  j["per_second_measured"] = per_second_is_measured(v.duration_s);
  j["reference"] = {{"integrator", v.reference_run.integrator},
                    {"tolerance", v.reference_tolerance},
                    {"wall_s", v.reference_wall_s},
                    {"stability", run_json(v.reference_run)},
                    {"change_when_tolerance_halved", comparison_json(v.reference_change)}};
  j["steady_window"] = {{"t_start_s", v.window.t_start},
                        {"revolutions", v.window.revolutions},
                        {"whole_run", v.window.whole_run},
                        {"how", v.window.how}};
  j["extraction_ms"] = v.extraction_ms;
  j["extraction_stages_ms"] = {{"system_build", v.extraction_stages.system_build_ms},
                               {"assembly", v.extraction_stages.assembly_ms},
                               {"kinetostatics", v.extraction_stages.kinetostatics_ms}};
  nlohmann::json ex = nlohmann::json::array();
  for (const auto& e : v.extractions)
    ex.push_back({{"grid_deg", e.grid_deg},
                  {"ms", e.ms},
                  {"kinetostatic_calls", e.calls},
                  {"points", e.points}});
  j["extractions"] = ex;
  j["headline_quantity"] = v.headline_quantity;
  j["quantities"] = v.quantities;
  nlohmann::json not_given = nlohmann::json::array();
  for (const auto& [name, why] : v.reactions_not_given) not_given.push_back({{"reaction", name}, {"why", why}});
  j["reactions_not_given"] = not_given;
  j["joint_output_quantities"] = v.joint_output_quantities;
  j["matched_error_target"] = v.matched_target;
  j["speedup_at_matched_error"] =
      v.speedup_at_matched_error ? num(*v.speedup_at_matched_error) : nullptr;
  j["matched_full"] =
      v.matched_full >= 0 ? run_json(v.runs[v.matched_full]) : nlohmann::json(nullptr);
  j["matched_reduced"] =
      v.matched_reduced >= 0 ? run_json(v.runs[v.matched_reduced]) : nlohmann::json(nullptr);
  // The settings to use for this scene, chosen from the measurements (validate/harness/pareto.hpp).
  j["recommended_reduced"] =
      v.recommended >= 0 ? run_json(v.runs[v.recommended]) : nlohmann::json(nullptr);
  // false: no run was within the target on every judged quantity; the recommended one is on the
  // speed and the headline quantity, its misses in the verdicts.
  j["recommended_on_all_quantities"] = v.recommended_on_all;
  j["showcase_reduced"] =
      v.showcase_run >= 0 ? run_json(v.runs[v.showcase_run]) : nlohmann::json(nullptr);
  // The grid rdyn's commands take for this scene by default (10°, halved while it does not
  // resolve the mechanism): the showcase's and the default thresholds' grid.
  j["default_grid_deg"] = v.default_grid_deg;
  j["default_grid_check"] = grid_check_json(v.default_grid_check);
  add_first_screen_json(v, j);
  if (v.budget)
    j["error_budget"] = {
        {"quantity", v.headline_quantity}, {"reference", num(v.budget->reference)},
        {"table", num(v.budget->table)},   {"integration", num(v.budget->integration)},
        {"total", num(v.budget->total)},   {"table_run", v.budget->table_run},
        {"output_interpolation", num(v.budget->output_interpolation)}};
  nlohmann::json conv = nlohmann::json::array();
  for (const auto& s : v.convergence) {
    nlohmann::json pts = nlohmann::json::array();
    for (const auto& [g, e] : s.points) pts.push_back({g, num(e)});
    conv.push_back({{"interpolation", s.interpolation}, {"points", pts}, {"order", num(s.order)}});
  }
  j["convergence"] = {
      {"quantity", v.headline_quantity}, {"floor", num(v.convergence_floor)}, {"series", conv}};
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : v.runs) runs.push_back(run_json(r));
  j["runs"] = runs;
  j["full_model_timing"] = v.full_timing;
  // Peer engines (issue #11): each ladder's runs and the reduced model's speedup over it.
  nlohmann::json peers = nlohmann::json::array();
  for (const auto& p : v.peers) {
    nlohmann::json pr = nlohmann::json::array();
    for (const auto& r : p.runs) pr.push_back(run_json(r));
    peers.push_back({{"engine", p.engine},
                     {"version", p.version},
                     {"integrator", p.integrator},
                     {"how", p.how},
                     {"runs", pr},
                     {"speedup_at_matched_error",
                      p.speedup_at_matched_error ? num(*p.speedup_at_matched_error) : nlohmann::json(nullptr)},
                     {"matched_peer", p.matched_peer >= 0 ? run_json(p.runs[p.matched_peer]) : nlohmann::json(nullptr)},
                     {"matched_reduced",
                      p.matched_reduced >= 0 ? run_json(v.runs[p.matched_reduced]) : nlohmann::json(nullptr)}});
  }
  j["peers"] = peers;
  if (v.calibration) j["calibration"] = calibration_json(v);
  if (v.drive_cycle) j["drive_cycle"] = drive_cycle_json(*v.drive_cycle);
  if (v.calibrated_run) j["calibrated_run"] = calibrated_run_json(*v.calibrated_run);
  nlohmann::json th = nlohmann::json::array();
  for (const auto& t : v.thresholds)
    th.push_back({{"quantity", t.threshold.quantity},
                  {"grid_deg", t.threshold.grid_deg},
                  {"max_error", t.threshold.max_error},
                  {"error", num(t.error)},
                  {"pass", t.pass},
                  {"run", t.run}});
  j["thresholds"] = th;
  j["thresholds_are_defaults"] = v.default_thresholds;
  j["status"] = v.pass ? "pass" : "fail";
  j["failures"] = v.failures;
  j["figures"] = figures_json(v);
  return j;
}

}  // namespace rdyn::validate
