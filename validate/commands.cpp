#include "validate/commands.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/build_reduced.hpp"
#include "validate/calibrate.hpp"
#include "validate/harness.hpp"
#include "validate/report.hpp"
#include "validate/sweep.hpp"
#include "validate/progress.hpp"
#include "validate/output_dir.hpp"
#include "validate/timeseries_csv.hpp"

namespace rdyn::validate {

namespace {

std::vector<models::Override> overrides_of(const std::vector<std::string>& sets) {
  std::vector<models::Override> overrides;
  for (const auto& s : sets) overrides.push_back(models::parse_override(s));
  return overrides;
}

models::Scene load(const std::string& scene, const std::vector<std::string>& sets) {
  return models::load_scene(scene, overrides_of(sets));
}

// Writes text to path through a temporary file and a rename (no half-written output).
void write_file_atomically(const std::string& path, const std::string& text) {
  namespace fs = std::filesystem;
  const fs::path target = fs::absolute(path);
  std::error_code ec;
  if (!fs::is_directory(target.parent_path(), ec))
    throw OutputError(path + ": cannot write: folder '" + target.parent_path().string() + "' does not exist");
  const std::string tmp = target.string() + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary);
    f << text;
    if (!f) {
      fs::remove(tmp, ec);
      throw OutputError(path + ": cannot write");
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw OutputError(path + ": cannot write: " + ec.message());
  }
}

void write_json(const std::string& path, const nlohmann::json& j) {
  std::ofstream f(path);
  f << j.dump(2) << "\n";
  if (!f) throw OutputError(path + ": cannot write");
}

}  // namespace

int run_simulate(const SimulateArgs& a) {
  const models::Scene scene = load(a.scene, a.sets);
  const double duration = std::isnan(a.duration) ? scene.simulation.duration_s : a.duration;
  const double dt_out = std::isnan(a.dt_out) ? scene.simulation.output_interval_s : a.dt_out;
  const double tolerance = std::isnan(a.tolerance) ? scene.simulation.tolerance : a.tolerance;
  if (!(duration > 0) || !(dt_out > 0) || !(tolerance > 0 && tolerance < 1))
    throw models::SceneError(a.scene, 0, "--duration/--dt-out/--tolerance", "must be positive (tolerance < 1)");
  OutputDir out(a.out);  // fails early on an unwritable folder

  nlohmann::json run = {{"scene", scene.name},     {"scene_file", scene.source_file}, {"model", a.model},
                        {"duration_s", duration},  {"output_interval_s", dt_out}};
  models::TimeSeries ts;
  if (a.model == "full") {
    engine::FullModelOptions mo;
    mo.route = a.route == "reaction" ? engine::ConstraintForceRoute::Reaction : engine::ConstraintForceRoute::Actuator;
    engine::FullModel model(scene, mo);
    engine::ForwardOptions opt{duration, dt_out, tolerance, a.integrator};
    ts = engine::simulate_full(model, opt);
    run.update({{"tolerance", tolerance},
                {"integrator", a.integrator},
                {"constraint_force_route", a.route},
                {"simbody_bodies", model.num_simbody_bodies()},
                {"max_loop_gap_m", ts.stats.max_constraint_error}});
  } else {
    reduced::Samples samples;
    double extraction_ms = 0.0;
    if (!a.table.empty()) {
      samples = reduced::read_samples_csv(a.table);
      run["table"] = a.table;
    } else {
      auto e = extract_from_full(scene, a.grid_deg, reduced::parse_method(a.method));
      samples = std::move(e.samples);
      extraction_ms = e.extraction_ms;
      run.update({{"grid_deg", a.grid_deg}, {"method", a.method}, {"kinetostatic_calls", e.calls}});
    }
    const auto model = reduced::make_reduced_model(samples, scene, reduced::parse_interpolation(a.interpolation),
                                                   a.energy_consistent);
    reduced::ReducedOptions opt{duration, dt_out, a.reduced_tolerance, a.reduced_integrator, a.fixed_step};
    ts = reduced::simulate_reduced(model, scene.initial.q, scene.initial.qdot, opt);
    run.update({{"interpolation", a.interpolation},
                {"energy_consistent_m2", a.energy_consistent},
                {"integrator", a.reduced_integrator},
                {"tolerance", a.reduced_tolerance},
                {"extraction_ms", extraction_ms},
                {"events", ts.stats.events}});
  }
  write_timeseries_csv(out.file("timeseries.csv"), ts);
  const auto eb = energy_balance(ts);
  run.update({{"steps_taken", ts.stats.steps_taken},
              {"steps_attempted", ts.stats.steps_attempted},
              {"smallest_step_s", ts.stats.smallest_step_s},
              {"wall_time_s", ts.stats.wall_time_s},
              {"wall_time_per_simulated_s", ts.stats.wall_time_s / duration},
              {"energy_balance_residual_J", eb.max_residual_J},
              {"energy_scale_J", eb.energy_scale_J}});
  write_json(out.file("run.json"), run);
  out.commit();
  std::fprintf(stderr, "%s\n",
               fmt::format("rdyn: {} ({} model) {:.3g} s simulated in {:.3g} s wall, {} steps; energy balance "
                           "residual {:.3g} J of {:.3g} J; wrote {}/timeseries.csv",
                           scene.name, a.model, duration, ts.stats.wall_time_s, ts.stats.steps_taken,
                           eb.max_residual_J, eb.energy_scale_J, a.out)
                   .c_str());
  return 0;
}

int run_extract(const ExtractArgs& a) {
  const models::Scene scene = load(a.scene, a.sets);
  const auto method = reduced::parse_method(a.method);
  // Write beside the target and rename, so a failure leaves no half-written table.
  namespace fs = std::filesystem;
  const fs::path target = fs::absolute(a.out);
  std::error_code ec;
  if (!fs::is_directory(target.parent_path(), ec))
    throw OutputError(a.out + ": cannot write: folder '" + target.parent_path().string() + "' does not exist");
  const auto e = extract_from_full(scene, a.grid_deg, method);
  const std::string tmp = target.string() + ".tmp";
  try {
    reduced::write_samples_csv(tmp, e.samples);
  } catch (const reduced::TableError& err) {
    fs::remove(tmp, ec);
    throw OutputError(err.what());
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw OutputError(a.out + ": cannot write: " + ec.message());
  }
  std::fprintf(stderr, "%s\n",
               fmt::format("rdyn: extracted {} ({}, {}° grid, {} points) in {:.3g} ms with {} kinetostatic calls; "
                           "wrote {}",
                           scene.name, a.method, a.grid_deg, e.samples.q.size(), e.extraction_ms, e.calls, a.out)
                   .c_str());
  return 0;
}

int run_calibrate(const CalibrateArgs& a) {
  const auto base = overrides_of(a.sets);
  const models::Scene scene = models::load_scene(a.scene, base);
  if (!a.write_scene.empty()) {  // fail early on an unwritable destination
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(fs::absolute(a.write_scene).parent_path(), ec))
      throw OutputError(a.write_scene + ": cannot write: its folder does not exist");
  }
  CalibrationOptions opt;
  opt.cadence_hz = a.cadence_hz;
  opt.power_w = a.power_w;
  opt.grid_deg = a.grid_deg;
  opt.interpolation = a.interpolation;
  Progress progress;
  const auto r = calibrate(scene, opt, progress);
  nlohmann::json j = {
      {"scene", scene.name},
      {"target_cadence_hz", a.cadence_hz},
      {"target_power_w", a.power_w},
      {"hip_torque_Nm", r.torque_Nm},
      {"initial_guess_Nm", r.initial_guess_Nm},
      {"resistance_coefficient", r.resistance_coefficient},
      {"mean_cadence_hz_reduced", r.mean_cadence_hz_reduced},
      {"mean_cadence_hz_full", r.mean_cadence_hz_full},
      {"mean_power_w", r.mean_power_w},
      {"peak_knee_force_N", r.force_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.peak_force_N)},
      {"peak_force_full_N", r.force_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.peak_force_full_N)},
      {"force_name", r.force_name},
      {"speed_fluctuation", r.speed_fluctuation},
      {"speed_fluctuation_full", r.speed_fluctuation_full},
      {"drive_work_per_rev_per_Nm", r.drive_work_per_rev_per_Nm},
      {"steady_q", r.steady_q},
      {"steady_qdot", r.steady_qdot},
      {"steady_cycles_computed", r.evaluations},
      {"wall_time_s", r.wall_time_s},
  };
  if (!a.write_scene.empty()) {
    write_file_atomically(a.write_scene, calibrated_scene_yaml(a.scene, base, scene, opt, r));
    j["written_scene"] = a.write_scene;
  }
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}

namespace {

// One scene's validation into `dir`; the scene-level summary entry for a suite.
nlohmann::json validate_one(const models::Scene& scene, const ValidationOptions& opt, const std::string& dir,
                            Progress& progress, bool& pass) {
  const ValidationResult v = run_validation(scene, opt, progress);
  write_validation_report(v, dir);
  pass = v.pass;
  nlohmann::json j = {{"name", v.scene}, {"file", v.scene_file}, {"status", v.pass ? "pass" : "fail"},
                      {"note", v.note}};
  const nlohmann::json full = summary_json(v);
  for (const char* k : {"speedup_at_matched_error", "extraction_ms", "thresholds", "reference", "steady_window",
                        "headline", "matched_full", "matched_reduced"})
    if (full.contains(k)) j[k] = full[k];
  if (v.showcase_run >= 0) {
    nlohmann::json sc = full["runs"][v.showcase_run];
    j["reduced_10deg"] = sc;
  }
  // Stability metrics of both models: the reference's and the default reduced run's energy
  // balance, drift per cycle, constraint violation, accepted/rejected steps, smallest step.
  j["stability"] = {{"full", full["reference"]["stability"]},
                    {"reduced", v.showcase_run >= 0 ? full["runs"][v.showcase_run] : nlohmann::json(nullptr)}};
  return j;
}

}  // namespace

int run_sweep_command(const SweepArgs& a) {
  SweepOptions o;
  o.scene = a.scene;
  o.sets = a.sets;
  o.cadence_hz = a.cadence_hz;
  o.power_w = a.power_w;
  o.threads = a.threads;
  o.grid_deg = a.grid_deg;
  if (std::sscanf(a.shard.c_str(), "%d/%d", &o.shard, &o.shards) != 2)
    throw models::SceneError("", 0, "--shard", "expected i/N, got '" + a.shard + "'");
  if (a.vary.empty()) throw models::SceneError("", 0, "--vary", "give at least one key=a:b:n");
  for (const auto& v : a.vary) o.axes.push_back(parse_sweep_axis(v));
  {  // fail early on an unwritable destination
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(fs::absolute(a.out).parent_path(), ec))
      throw OutputError(a.out + ": cannot write: its folder does not exist");
  }
  const std::string csv = run_sweep(o, Progress().enabled());
  write_file_atomically(a.out, csv);
  std::fprintf(stderr, "rdyn: sweep shard %s wrote %s\n", a.shard.c_str(), a.out.c_str());
  return 0;
}

int run_validate(const ValidateArgs& a) {
  namespace fs = std::filesystem;
  Progress progress;
  ValidationOptions opt;
  if (!a.suite.empty() && !a.scene.empty()) throw models::SceneError(a.scene, 0, "", "give a scene or --suite, not both");
  if (a.suite.empty() && a.scene.empty()) throw models::SceneError("", 0, "", "give a scene or --suite FOLDER");
  if (a.scene.empty()) {
    std::error_code ec;
    if (!fs::is_directory(a.suite, ec)) throw models::SceneError(a.suite, 0, "", "not a folder of scenes");
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(a.suite))
      if (e.path().extension() == ".yaml" || e.path().extension() == ".yml") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    if (files.empty()) throw models::SceneError(a.suite, 0, "", "the folder has no .yaml scenes");
    OutputDir out(a.out);
    opt.quick = !a.thorough;
    nlohmann::json scenes = nlohmann::json::array();
    bool all_pass = true;
    std::string rows;
    for (size_t i = 0; i < files.size(); ++i) {
      const std::string stem = fs::path(files[i]).stem().string();
      progress.note(fmt::format("[{}/{}] {}", i + 1, files.size(), files[i]));
      nlohmann::json entry;
      try {
        const auto scene = models::load_scene(files[i], overrides_of(a.sets));
        fs::create_directory(out.file(stem));
        bool pass = false;
        entry = validate_one(scene, opt, out.file(stem), progress, pass);
        all_pass &= pass;
      } catch (const std::exception& e) {  // a failing scene does not stop the others
        entry = {{"name", stem}, {"file", files[i]}, {"status", "error"}, {"error", e.what()}};
        all_pass = false;
      }
      entry["report"] = stem + "/report.html";
      const std::string status = entry["status"];
      rows += fmt::format("<tr><td class=l><a href='{0}/report.html'>{0}</a></td><td class={1}>{1}</td><td class=l>{2}</td></tr>",
                          stem, status, entry.contains("error") ? std::string(entry["error"]) : std::string(entry.value("note", "")));
      scenes.push_back(entry);
    }
    nlohmann::json summary = {{"suite", a.suite}, {"status", all_pass ? "pass" : "fail"}, {"scenes", scenes}};
    {
      std::ofstream f(out.file("summary.json"));
      f << summary.dump(2) << "\n";
    }
    {
      std::ofstream f(out.file("index.html"));
      f << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>rdyn suite</title><style>body{font-family:sans-serif;"
           "max-width:1000px;margin:2em auto}td,th{border:1px solid #ccc;padding:3px 6px}table{border-collapse:collapse}"
           ".pass{color:#070}.fail,.error{color:#a00}</style></head><body><h1>rdyn validation suite: "
        << a.suite << "</h1><table><tr><th>scene</th><th>status</th><th>what it tests / error</th></tr>" << rows
        << "</table></body></html>\n";
    }
    out.commit();
    std::fprintf(stderr, "rdyn: suite %s: %s; wrote %s/index.html\n", a.suite.c_str(), all_pass ? "all scenes pass" : "FAILURES",
                 a.out.c_str());
    return all_pass ? 0 : 1;
  }
  const auto scene = load(a.scene, a.sets);
  OutputDir out(a.out);
  opt.quick = a.quick;
  bool pass = false;
  const ValidationResult v = run_validation(scene, opt, progress);
  write_validation_report(v, out.file(""));
  pass = v.pass;
  out.commit();
  std::printf("%s\n\nReport: %s/report.html\n", headline(v).c_str(), a.out.c_str());
  return pass ? 0 : 1;
}

}  // namespace rdyn::validate
