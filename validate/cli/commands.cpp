#include "validate/cli/commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <cctype>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "models/scene_yaml.hpp"
#include "models/timeseries.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/unstable_rest.hpp"
#include "validate/analysis/table_check.hpp"
#include "models/scene_hash.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/calibrated_scene.hpp"
#include "validate/cli/cli_limits.hpp"
#include "validate/io/escape.hpp"
#include "validate/harness/harness.hpp"
#include "validate/harness/grid_check.hpp"
#include "validate/cli/inspect.hpp"
#include "validate/cli/animate_command.hpp"
#include "engine/inspect.hpp"
#include "validate/report/report.hpp"
#include "validate/report/cycle_animation.hpp"
#include "validate/analysis/cycle_run.hpp"
#include "validate/harness/summary.hpp"
#include "validate/analysis/sweep.hpp"
#include "validate/cli/sweep_axis.hpp"
#include "validate/io/progress.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/harness/peers.hpp"
#include "validate/report/timeseries_csv.hpp"
#include "reduced/table_resolution.hpp"
#include "models/mjcf_export.hpp"

namespace rdyn::validate {

std::vector<models::Override> overrides_of(const std::vector<std::string>& sets) {
  std::vector<models::Override> overrides;
  for (const auto& s : sets) overrides.push_back(models::parse_override(s));
  return overrides;
}

models::Scene load(const std::string& scene, const std::vector<std::string>& sets) {
  return models::load_scene(scene, overrides_of(sets));
}

namespace {

void require_in(const std::string& option, double v, double lo, double hi, const char* unit) {
  if (!(std::isfinite(v) && v >= lo && v <= hi))
    throw ArgumentError(fmt::format("{}: must be a finite number in [{:g}, {:g}]{} (got {})", option, lo, hi, unit, v));
}

void require_positive_up_to(const std::string& option, double v, double hi, const char* unit) {
  if (!(std::isfinite(v) && v > 0 && v <= hi))
    throw ArgumentError(fmt::format("{}: must be a finite number in (0, {:g}]{} (got {})", option, hi, unit, v));
}

void require_grid(const std::string& option, double g) {
  require_in(option, g, cli_limits::kMinGrid_deg, cli_limits::kMaxGrid_deg, " deg");
  const double n = 360.0 / g;
  if (std::abs(n - std::round(n)) > 1e-9 * n)
    throw ArgumentError(fmt::format("{}: {:g}° does not divide 360° into whole steps", option, g));
}

// Duration, output interval and the number of rows they make.
void require_timing(double duration, double dt_out) {
  // At least one shortest output interval: 1e-300 s was refused as "--dt-out: must be in [1e-06, 1e-300]".
  require_in("--duration", duration, cli_limits::kMinOutputInterval_s, cli_limits::kMaxDuration_s, " s");
  require_in("--dt-out", dt_out, cli_limits::kMinOutputInterval_s, duration, " s (and at most --duration)");
  // Rows as the simulations count them (t = 0, then one per interval, the last at the duration:
  // models::calc_output_rows), so that no run the CLI accepts meets their own, wordier refusal.
  const double rows = static_cast<double>(models::calc_output_rows(duration, dt_out)) + 1;
  if (rows > cli_limits::kMaxOutputRows)
    throw ArgumentError(fmt::format("--dt-out: {:g} s over {:g} s makes {:.8g} rows; at most {:g}", dt_out, duration,
                                    rows, cli_limits::kMaxOutputRows));
}

// Recognisers of rdyn's own single-file outputs, so a re-run may replace them.
bool is_rdyn_table(const std::string& head) { return head.rfind("# rdyn-table", 0) == 0; }
bool is_rdyn_mjcf(const std::string& head) { return head.rfind("<mujoco model=", 0) == 0; }
bool is_rdyn_calibrated_scene(const std::string& head) { return head.rfind("# Calibrated by `rdyn calibrate`", 0) == 0; }
void write_json(const std::string& path, const nlohmann::json& j) { write_text_file(path, j.dump(2) + "\n"); }

bool is_rdyn_sweep(const std::string& head) {
  // Since issue #28 every part starts with its metadata line; before, shard 0 started with the
  // header and other shards with a case row "<index>,...,ok|error,".
  if (head.rfind("# rdyn-sweep ", 0) == 0 || head.rfind("case,", 0) == 0) return true;
  const std::string first = head.substr(0, head.find('\n'));
  return !first.empty() && std::isdigit(static_cast<unsigned char>(first[0])) &&
         (first.find(",ok,") != std::string::npos || first.find(",error,") != std::string::npos);
}

}  // namespace

// A periodic table too coarse for its mechanism gives wrong accelerations and forces with exit 0
// (issue #23: a Jansen leg's 10° table missed q̈ by 6 % and a reaction by 60 %, a five-bar geared
// 2:1 missed q̈ by 40 %): the half-grid miss of m1 (reduced/table_resolution.hpp) flags it on
// standard error and in run.json (`table_m1_half_grid_miss`). Range tables are not checked.
void warn_coarse_table(const reduced::Samples& s, nlohmann::json& run) {
  const int c = s.column("m1");
  if (!s.periodic || c < 0) return;
  const double miss = reduced::calc_half_grid_miss(s.columns[c]);
  if (!std::isfinite(miss)) return;
  run["table_m1_half_grid_miss"] = miss;
  if (miss <= reduced::kCoarseTableMiss) return;
  const double step_deg = s.step * 180.0 / 3.14159265358979323846;
  std::fprintf(stderr,
               "rdyn: warning: the %g° table looks too coarse for this mechanism: its m1 interpolated from every "
               "other grid point misses the others by %.2g %% of its peak (above %g %%), and the reduced model's q̈, "
               "forces and reactions may be off by as much or more; use a finer --grid-deg (rdyn validate measures "
               "the errors)\n",
               step_deg, 100 * miss, 100 * reduced::kCoarseTableMiss);
}

void check_simulate_args(const models::Scene& scene, const SimulateArgs& a) {
  const double duration = a.duration.value_or(scene.simulation.duration_s);
  const double dt_out = a.dt_out.value_or(scene.simulation.output_interval_s);
  const double tolerance = a.tolerance.value_or(scene.simulation.tolerance);
  require_timing(duration, dt_out);
  // Every number given is checked, also those of the other model: a typo is never ignored.
  require_in("--tolerance", tolerance, cli_limits::kMinTolerance, cli_limits::kMaxTolerance, "");
  require_in("--reduced-tolerance", a.reduced_tolerance, cli_limits::kMinTolerance, cli_limits::kMaxTolerance, "");
  require_grid("--grid-deg", a.grid_deg);
  // A table has its grid: a --grid-deg beside it would be ignored in silence.
  if (!a.table.empty() && a.grid_given)
    throw ArgumentError("--grid-deg: the --table has its own grid; give one or the other");
  require_in("--fixed-step", a.fixed_step, cli_limits::kMinFixedStep_s, cli_limits::kMaxFixedStep_s, " s");
  if (a.model == "reduced" && a.reduced_integrator == "rk4-fixed" &&
      duration / a.fixed_step > cli_limits::kMaxFixedSteps)
    throw ArgumentError(fmt::format("--fixed-step: {:g} s over {:g} s makes {:.3g} steps; at most {:g}", a.fixed_step,
                                    duration, duration / a.fixed_step, cli_limits::kMaxFixedSteps));
}

// The reduced model's run of simulate_scene on `table`, the --table file or a fresh extraction at
// start_grid_deg (refined as extract_resolving refines a default one); grid_used_deg gets the
// extraction's grid (0 for a table).
models::TimeSeries simulate_reduced_once(const models::Scene& scene, const SimulateArgs& a, const reduced::Samples* table,
                                         double duration, double dt_out, double start_grid_deg, double& grid_used_deg,
                                         nlohmann::json& run) {
  models::TimeSeries ts;
  grid_used_deg = 0;
  // Joint outputs: the table and the model carry one constraint line per reaction component.
  // `reactions: all` gives those the reduced model can and names the others.
  const models::Scene oscene = reduced_output_scene(scene, run);
  const models::Scene rscene = reduced::wants_joint_outputs(oscene) ? reduced::with_reaction_requests(oscene) : oscene;
  reduced::Samples samples;
  double extraction_ms = 0.0;
  if (table) {  // a table in memory (the Python module's Table)
    samples = *table;
    run["table"] = table->file.empty() ? std::string("(in memory)") : table->file;
  } else if (!a.table.empty()) {
    // Checked before opening: a FIFO without a writer would block (models::non_regular_file_kind).
    if (const std::string kind = models::non_regular_file_kind(a.table); !kind.empty())
      throw reduced::TableError(a.table + ": not a regular file (" + kind + "): give a table written by rdyn extract");
    samples = reduced::read_samples_csv(a.table);
    run["table"] = a.table;
  } else {
    double grid = start_grid_deg;
    auto e = extract_resolving(rscene, start_grid_deg, a.grid_given, reduced::parse_method(a.method), grid);
    grid_used_deg = grid;
    samples = std::move(e.samples);
    extraction_ms = e.extraction_ms;
    run.update({{"grid_deg", grid}, {"method", a.method}, {"kinetostatic_calls", e.calls}});
    if (grid != a.grid_deg) run["grid_refined_from_deg"] = a.grid_deg;
    if (e.range) {  // range table: its span [rad or m] and what ends it
      run["independent_range"] = {{"min", e.range->min}, {"max", e.range->max}, {"min_edge", e.range->min_edge},
                                  {"max_edge", e.range->max_edge}};
      if (e.dead_min && e.dead_max) run["dead_points"] = {*e.dead_min, *e.dead_max};
    }
  }
  // A table read from a file (here or by the Python module) without a content checksum: its
  // values and annotations against a fresh extraction (validate/analysis/table_check.hpp),
  // before the model is built from them (an m1 of 1e99 overshot to a negative interpolant there,
  // reported without a line); a table of another scene keeps make_reduced_model's message.
  if (!samples.file.empty() && !samples.content_checked && samples.scene_hash == models::scene_hash(rscene)) {
    std::fprintf(stderr,
                 "rdyn: warning: %s has no content checksum (written before rdyn recorded one): checking it "
                 "against a fresh extraction of its scene; extract it again to skip this\n",
                 samples.file.c_str());
    check_table_against_scene(samples, rscene);
  }
  const auto model = reduced::make_reduced_model(samples, rscene, reduced::parse_interpolation(a.interpolation),
                                                 a.energy_consistent);
  // A table of the same mechanism extracted without joint outputs (its hash does not cover
  // outputs.joints or shaking, which add no constraint line): named with its file before the run (after
  // make_reduced_model, whose scene check comes first).
  if (reduced::wants_joint_outputs(oscene) && !samples.file.empty())
    for (const auto& j : oscene.joints)
      if (samples.column("p_" + j.name) < 0)
        throw reduced::TableError(fmt::format(
            "table {} has no column 'p_{}', which the scene's joint outputs (outputs.joints, reactions or shaking) "
            "need: it was extracted from the scene without them; extract it again with `rdyn extract` for this "
            "scene and its outputs",
            samples.file, j.name));
  warn_coarse_table(samples, run);
  reduced::ReducedOptions opt{duration, dt_out, a.reduced_tolerance, a.reduced_integrator, a.fixed_step};
  ts = reduced::simulate_reduced(model, scene.initial.q, scene.initial.qdot, opt);
  reduced::check_energy_balance(
      ts, 0.01,
      a.reduced_integrator == "rk4-fixed" ? fmt::format("rk4-fixed at {:g} s steps", opt.fixed_step_s)
                                          : fmt::format("{} at tolerance {:g}", a.reduced_integrator, a.reduced_tolerance));
  if (reduced::wants_joint_outputs(oscene)) reduced::add_joint_outputs(oscene, model, ts);
  // The interpolant the table was built with (a range table's not-a-knot spline stands in for
  // fourier), not the option's name.
  run.update({{"interpolation", model.table.fit},
              {"energy_consistent_m2", a.energy_consistent},
              {"integrator", a.reduced_integrator},
              {"tolerance", a.reduced_tolerance},
              {"extraction_ms", extraction_ms},
              {"events", ts.stats.events}});
  return ts;
}

// The default grid's run against the run on half its grid (validate/harness/grid_check.hpp): the
// finer run is taken while some column changes more than kGridCheckMaxChange of its peak, and
// run.json's grid_check says what was compared; a run that did not converge is written with a
// warning naming the column.
models::TimeSeries check_default_grid(const models::Scene& scene, const SimulateArgs& a, double duration,
                                      double dt_out, models::TimeSeries ts, double grid_deg, nlohmann::json& run) {
  struct GridRun {
    models::TimeSeries ts;
    nlohmann::json run;
  };
  SimulateArgs given = a;
  given.grid_given = true;  // each grid as asked: the check does the halving
  GridCheck check;
  GridRun kept = check_grid_by_runs(
      GridRun{std::move(ts), run}, grid_deg,
      [&](double g) {
        GridRun r{{}, run};
        double used = 0;
        r.ts = simulate_reduced_once(scene, given, nullptr, duration, dt_out, g, used, r.run);
        return r;
      },
      true, check);
  run = std::move(kept.run);
  run["grid_check"] = grid_check_json(check);
  if (!check.not_compared.empty())
    std::fprintf(stderr,
                 "rdyn: warning: the reduced run on the %g° table was not checked against one on half its grid, "
                 "which failed: %s (run.json: grid_check)\n",
                 check.grid_deg, check.not_compared.c_str());
  else if (!check.verified)
    std::fprintf(stderr,
                 "rdyn: warning: the reduced run has not converged in its grid: on the %g° and %g° tables %s differs "
                 "by %.2g %% of its peak (more than %g %%); the %g° run is written: compare it with --model full "
                 "(run.json: grid_check)\n",
                 check.coarser_grid_deg, check.grid_deg, check.column.c_str(), 100 * check.change,
                 100 * kGridCheckMaxChange, check.grid_deg);
  return std::move(kept.ts);
}

// A default grid (no --grid-deg, no table) whose run misses its own energy balance is halved and
// the run repeated, down to kMinAutoGrid_deg: m1's half-grid miss (extract_resolving) does not
// see every table too coarse for its motion — the high-saddle bicycle's 2.5° table resolves m1
// (miss below 1e-3) while its run, through the steep me2 of an almost straight leg, misses its
// energy balance by 3.7 %; refined (to 0.3125°, where m1's miss also asks for it) it balances to
// 0.139 J of 1.81e3 J. The run kept is then checked against the run on half its grid
// (check_default_grid).
models::TimeSeries simulate_reduced_refining(const models::Scene& scene, const SimulateArgs& a,
                                             const reduced::Samples* table, double duration, double dt_out,
                                             nlohmann::json& run) {
  double start = a.grid_deg, used = 0;
  for (;;) {
    try {
      auto ts = simulate_reduced_once(scene, a, table, duration, dt_out, start, used, run);
      if (used > 0 && !a.grid_given) ts = check_default_grid(scene, a, duration, dt_out, std::move(ts), used, run);
      return ts;
    } catch (const reduced::EnergyBalanceError&) {
      // The table is refined only under the default integrator: with a step or tolerance the user
      // gave, the miss may be theirs (a 1 s fixed step was re-extracted five times, then exit 1).
      const SimulateArgs defaults;
      const bool default_integrator =
          a.reduced_integrator == defaults.reduced_integrator && a.reduced_tolerance == defaults.reduced_tolerance;
      const bool refinable = !table && a.table.empty() && !a.grid_given && used > 0 && default_integrator;
      if (!refinable || used / 2 < kMinAutoGrid_deg - 1e-9) throw;
      std::fprintf(stderr, "rdyn: the reduced run on the %g° table misses its energy balance: extracting at %g°\n",
                   used, used / 2);
      start = used / 2;
    }
  }
}

SimulateRun simulate_scene(const models::Scene& scene, const SimulateArgs& a, const reduced::Samples* table) {
  check_simulate_args(scene, a);
  const double duration = a.duration.value_or(scene.simulation.duration_s);
  const double dt_out = a.dt_out.value_or(scene.simulation.output_interval_s);
  const double tolerance = a.tolerance.value_or(scene.simulation.tolerance);
  nlohmann::json run = {{"scene", scene.name},     {"scene_file", scene.source_file}, {"model", a.model},
                        {"duration_s", duration},  {"output_interval_s", dt_out}};
  {  // The assembled configuration (every joint coordinate at t = 0), with its warnings.
    const auto assembly = engine::calc_assembly(engine::FullModel(scene));
    for (const auto& w : assembly.warnings) std::fprintf(stderr, "rdyn: warning: %s\n", w.c_str());
    run["assembly"] = assembly_json(assembly);
  }
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
                {"max_loop_gap_m", ts.stats.max_constraint_error},
                // Windows of rank loss crossed in the partitioned formulation (docs/theory.md §7a).
                {"singular_passages", ts.stats.singular_passages},
                {"rows_interpolated_at_rank_loss", ts.stats.interpolated_rows},
                {"events", ts.stats.events}});
    if (ts.stats.interpolated_rows > 0)
      std::fprintf(stderr,
                   "rdyn: warning: %ld output row(s) lie within ~1e-4 rad of a configuration where the loop Jacobian "
                   "loses rank: there the constraint forces and reactions are not determined, and those rows give the "
                   "interpolation of rows around it (a force that grows without bound toward it is not followed); "
                   "run.json: rows_interpolated_at_rank_loss\n",
                   ts.stats.interpolated_rows);
  } else {
    ts = simulate_reduced_refining(scene, a, table, duration, dt_out, run);
  }
  const auto eb = energy_balance(ts);
  if (const auto rest = find_unstable_rest(ts)) {
    const bool revolute = scene.find_joint(scene.independent)->type == models::JointType::Revolute;
    run["unstable_rest"] = {{"t_from_s", rest->t_from_s}, {"t_to_s", rest->t_to_s}, {"q", rest->q}};
    std::fprintf(stderr,
                 "rdyn: warning: the motion crept to rest near %s (t = %.4g to %.4g s) and then left it: an unstable "
                 "equilibrium, where when and which way it leaves is decided by differences far below the model's "
                 "accuracy (the full and reduced models, or two tolerances, may part from there); run.json: "
                 "unstable_rest\n",
                 reduced::describe_q(revolute, rest->q, 6).c_str(), rest->t_from_s, rest->t_to_s);
  }
  run.update({{"steps_taken", ts.stats.steps_taken},
              {"steps_attempted", ts.stats.steps_attempted},
              {"smallest_step_s", ts.stats.smallest_step_s},
              {"wall_time_s", ts.stats.wall_time_s},
              {"wall_time_per_simulated_s", ts.stats.wall_time_s / duration},
              {"energy_balance_residual_J", eb.max_residual_J},
              {"energy_scale_J", eb.energy_scale_J}});
  return {std::move(ts), std::move(run)};
}

int run_simulate(const SimulateArgs& a) {
  const models::Scene scene = load(a.scene, a.sets);
  check_simulate_args(scene, a);
  OutputDir out(a.out, a.force);  // fails early on an unusable folder
  const auto [ts, run] = simulate_scene(scene, a);
  const double duration = run["duration_s"].get<double>();
  const auto eb = energy_balance(ts);
  write_timeseries_csv(out.file("timeseries.csv"), ts);
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

Extraction extract_scene(const models::Scene& scene, double grid_deg, const std::string& method) {
  require_grid("--grid-deg", grid_deg);
  const auto m = reduced::parse_method(method);
  const models::Scene oscene =
      scene.outputs.reactions_all ? reduced::split_reduced_reactions(scene).scene : scene;  // as simulate
  return extract_from_full(reduced::wants_joint_outputs(oscene) ? reduced::with_reaction_requests(oscene) : oscene,
                           grid_deg, m);
}

bool is_rdyn_table_file(const std::string& head) { return is_rdyn_table(head); }

int run_extract(const ExtractArgs& a) {
  require_grid("--grid-deg", a.grid_deg);
  const models::Scene scene = load(a.scene, a.sets);
  reduced::parse_method(a.method);  // a bad method is refused before the destination is touched
  OutputFile out(a.out, a.force, is_rdyn_table);  // fails early on an unusable destination
  const auto e = extract_scene(scene, a.grid_deg, a.method);
  out.write(reduced::format_samples_csv(e.samples));
  out.commit();
  std::string range;  // range tables: the span and, when found, the dead points
  if (e.range) {
    const bool rev = e.samples.revolute;
    const double k = rev ? 180.0 / M_PI : 1.0;
    const char* unit = rev ? "°" : " m";
    range = fmt::format("; range [{:.9g}, {:.9g}]{} ({} / {})", e.range->min * k, e.range->max * k, unit,
                        e.range->min_edge, e.range->max_edge);
    if (e.dead_min && e.dead_max)
      range += fmt::format(", dead points at {:.9g}{} and {:.9g}{}", *e.dead_min * k, unit, *e.dead_max * k, unit);
  }
  // A range table's step follows from --grid-deg (reduced/extract.hpp, range_intervals): a slider's
  // grid is a length, and a range ending at dead points is sampled kDeadPointRefinement× finer.
  const std::string grid =
      e.samples.periodic
          ? fmt::format("{}° grid", a.grid_deg)
          : fmt::format("{:.6g}{} grid: {} intervals from a {}° grid{}",
                        e.samples.step * (e.samples.revolute ? 180 / M_PI : 1.0), e.samples.revolute ? "°" : " m",
                        e.samples.q.size() > 0 ? e.samples.q.size() - 1 : 0, a.grid_deg,
                        e.dead_min && e.dead_max ? ", ten times finer toward dead points" : "");
  std::fprintf(stderr, "%s\n",
               fmt::format("rdyn: extracted {} ({}, {}, {} points{}) in {:.3g} ms with {} kinetostatic calls; "
                           "wrote {}",
                           scene.name, a.method, grid, e.samples.q.size(), range, e.extraction_ms, e.calls, a.out)
                   .c_str());
  return 0;
}

int run_calibrate(const CalibrateArgs& a) {
  const auto base = overrides_of(a.sets);
  if (a.cadence_given) require_positive_up_to("--cadence-hz", a.cadence_hz, cli_limits::kMaxCadence_Hz, " Hz");
  if (a.power_given) require_positive_up_to("--power-w", a.power_w, cli_limits::kMaxPower_W, " W");
  require_grid("--grid-deg", a.grid_deg);
  const std::string text = models::read_scene_text(a.scene);  // once: the scene may be a stream
  const models::Scene scene = models::parse_scene(text, models::resolve_scene_path(a.scene), base);
  CalibrationOptions opt = check_calibrate_args(scene, a);
  // --write-scene with --force: a full-model miss still writes the scene (marked), then exit 1.
  opt.keep_unconfirmed = a.force && !a.write_scene.empty();
  if (!a.write_scene.empty()) check_writable(text, scene, opt);
  std::unique_ptr<OutputFile> out;  // fails early on an unusable destination
  if (!a.write_scene.empty()) out = std::make_unique<OutputFile>(a.write_scene, a.force, is_rdyn_calibrated_scene);
  Progress progress;
  const auto r = calibrate(scene, opt, progress);
  nlohmann::json j = calibration_json(scene, opt, r);
  if (out) {
    out->write(calibrated_scene_yaml(a.scene, text, base, scene, opt, r));
    out->commit();
    j["written_scene"] = a.write_scene;
  }
  if (!r.unconfirmed.empty())
    throw models::NumericalError(r.unconfirmed + "; the scene was written to " + a.write_scene +
                                 " all the same (--force), marked as not confirmed");
  std::printf("%s\n", j.dump(2).c_str());
  return 0;
}

CalibrationOptions check_calibrate_args(const models::Scene& scene, const CalibrateArgs& a) {
  if (a.cadence_given) require_positive_up_to("--cadence-hz", a.cadence_hz, cli_limits::kMaxCadence_Hz, " Hz");
  if (a.power_given) require_positive_up_to("--power-w", a.power_w, cli_limits::kMaxPower_W, " W");
  require_grid("--grid-deg", a.grid_deg);
  CalibrationOptions opt = calibration_options_of(scene, a.cadence_given ? a.cadence_hz : 0.0,
                                                  a.power_given ? a.power_w : 0.0, a.load);
  if (!a.cadence_given && !(scene.validation.calibrate_cadence_Hz > 0)) opt.cadence_hz = a.cadence_hz;
  if (a.grid_given) opt.grid_deg = a.grid_deg;
  opt.grid_given = a.grid_given || opt.grid_given;
  opt.interpolation = a.interpolation;
  return opt;
}

nlohmann::json calibration_json(const models::Scene& scene, const CalibrationOptions& opt,
                                const CalibrationResult& r) {
  auto number_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  const bool joint_torque = std::isfinite(r.torque_Nm);
  nlohmann::json j = {
      {"scene", scene.name},
      {"target_cadence_hz", opt.cadence_hz},
      {"target_power_w", opt.power_w > 0 ? nlohmann::json(opt.power_w) : nlohmann::json(nullptr)},
      {"load", r.load},
      {"load_kind", r.load_kind},
      {"load_value", r.load_value},
      {"load_unit", r.load_unit},
      {"initial_guess", r.initial_guess},
      {"grid_deg", number_or_null(r.grid_deg)},
      {"resistance_coefficient", number_or_null(r.resistance_coefficient)},
      {"mean_cadence_hz_reduced", r.mean_cadence_hz_reduced},
      {"mean_cadence_hz_full", number_or_null(r.mean_cadence_hz_full)},
      {"full_revolutions", r.full_duration_s > 0 ? nlohmann::json(r.full_revolutions) : nlohmann::json(nullptr)},
      {"full_duration_s", r.full_duration_s > 0 ? nlohmann::json(r.full_duration_s) : nlohmann::json(nullptr)},
      {"mean_power_w", r.mean_power_w},
      {"mean_dissipated_power_w", r.mean_dissipated_power_w},
      {"load_searches", r.load_searches},
      {"peak_force_N", r.force_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.peak_force_N)},
      {"peak_force_full_N", r.force_name.empty() ? nlohmann::json(nullptr) : number_or_null(r.peak_force_full_N)},
      {"force_name", r.force_name},
      {"speed_fluctuation", r.speed_fluctuation},
      {"speed_fluctuation_full", number_or_null(r.speed_fluctuation_full)},
      {"work_per_rev_per_unit", r.work_per_rev_per_unit},
      {"steady_q", r.steady_q},
      {"steady_qdot", r.steady_qdot},
      {"steady_cycles_computed", r.evaluations},
      {"wall_time_s", r.wall_time_s},
  };
  if (joint_torque) {  // the keys of joint-torque calibrations before loads were named (compatibility)
    j["drive_torque_Nm"] = r.torque_Nm;
    j["initial_guess_Nm"] = r.initial_guess;
    j["drive_work_per_rev_per_Nm"] = r.work_per_rev_per_unit;
  }
  if (std::isfinite(r.grid_deg) && r.grid_deg != opt.grid_deg) j["grid_refined_from_deg"] = opt.grid_deg;
  return j;
}


namespace {

// A sweep part's text, read whole: a part holds at most 1e6 rows of a few hundred bytes, so a
// larger file is not one (and is not read into memory).
constexpr std::uintmax_t kMaxPartBytes = std::uintmax_t{1} << 30;

std::string read_sweep_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw models::SceneError(path, 0, "file", "cannot read: no such file");
  if (!fs::is_regular_file(st)) throw models::SceneError(path, 0, "file", "not a regular file");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec || size > kMaxPartBytes)
    throw models::SceneError(path, 0, "file", "larger than 1 GiB: not a part of an rdyn sweep");
  std::ifstream f(path, std::ios::binary);
  std::string text(static_cast<size_t>(size), '\0');
  if (!f.read(text.data(), static_cast<std::streamsize>(size)))
    throw models::SceneError(path, 0, "file", "cannot read it");
  return text;
}

// Why the file at `path` does not already hold the plan's shard complete ("" when it does).
std::string why_not_complete(const std::string& path, const SweepPlan& plan, SweepPart& part) {
  try {
    part = parse_sweep_part(read_sweep_file(path), path);
  } catch (const models::SceneError& e) {
    return e.what();
  }
  if (part.id.sweep_hex != plan.id.sweep_hex || part.id.total != plan.id.total || part.header != plan.header)
    return "it holds another sweep (scene, axes or options differ)";
  if (part.range.shard != plan.range.shard || part.range.shards != plan.range.shards)
    return fmt::format("it holds shard {}/{}", part.range.shard, part.range.shards);
  if (!part.complete()) return fmt::format("it is partial (case {} is missing)", part.first_missing());
  return "";
}

// The line that ends a sweep shard, its merge or its skip: `done` says what was done; exit 1
// when cases failed (their rows are in `out`).
int report_sweep(const std::string& what, const std::string& done, long failed, const std::string& out) {
  if (failed > 0) {
    std::fprintf(stderr, "rdyn: %s: %s; %ld failed (rows with status 'error' in %s)\n", what.c_str(), done.c_str(),
                 failed, out.c_str());
    return 1;
  }
  std::fprintf(stderr, "rdyn: %s: %s; wrote %s\n", what.c_str(), done.c_str(), out.c_str());
  return 0;
}

int run_sweep_merge(const SweepArgs& a) {
  if (a.inputs.empty()) throw ArgumentError("--merge: give the part CSVs after OUT.csv");
  // The merged file replacing one of its own parts would lose that part (the same file by any
  // path: equivalent() compares device and inode).
  std::error_code ec;
  for (const auto& path : a.inputs)
    if (std::filesystem::equivalent(a.merge, path, ec))
      throw ArgumentError(fmt::format("--merge: the output {} is one of the parts ({}): write the merge elsewhere",
                                      a.merge, path));
  OutputFile out(a.merge, a.force, is_rdyn_sweep);  // fails early on an unusable destination
  std::vector<SweepPart> parts;
  for (const auto& path : a.inputs) parts.push_back(parse_sweep_part(read_sweep_file(path), path));
  const MergedSweep m = merge_sweep_parts(parts);
  out.write(m.csv);
  out.commit();
  return report_sweep("sweep merge", fmt::format("{} cases from {} parts", m.cases, parts.size()), m.failed, a.merge);
}

}  // namespace

SweepOptions check_sweep_args(const SweepArgs& a) {
  if (a.inputs.size() != 1)
    throw ArgumentError(fmt::format("sweep: give one scene (got {})", a.inputs.size()));
  SweepOptions o;
  o.scene = a.inputs.front();
  o.sets = a.sets;
  o.cadence_hz = a.cadence_hz.value_or(0.0);  // SweepOptions: 0 is the scene's
  o.power_w = a.power_w.value_or(0.0);
  o.load = a.load;
  o.threads = a.threads.value_or(0);  // 0: the hardware's threads
  o.grid_deg = a.grid_deg;
  o.grid_given = a.grid_given;
  o.peaks = a.peaks;  // checked against the scene by plan_sweep
  require_grid("--grid-deg", a.grid_deg);
  if (a.drive_cadence_hz) {  // a typed 0 is refused, not "no drive sweep"
    const double f = *a.drive_cadence_hz;
    if (!(std::isfinite(f) && f != 0 && std::abs(f) <= cli_limits::kMaxCadence_Hz))
      throw ArgumentError(fmt::format("--drive-cadence-hz: must be a finite, non-zero rate with |F| ≤ {:g} rev/s (got {})",
                                      cli_limits::kMaxCadence_Hz, f));
    o.drive_cadence_hz = f;
  }
  // A typed value is checked even when it is 0: `--threads 0` meant no default (issue #23).
  if (a.threads) require_in("--threads", *a.threads, 1, cli_limits::kMaxThreads, "");
  if (a.cadence_hz) require_positive_up_to("--cadence-hz", *a.cadence_hz, cli_limits::kMaxCadence_Hz, " Hz");
  if (a.power_w) require_positive_up_to("--power-w", *a.power_w, cli_limits::kMaxPower_W, " W");
  {
    int used = 0;
    if (std::sscanf(a.shard.c_str(), "%d/%d%n", &o.shard, &o.shards, &used) != 2 ||
        used != static_cast<int>(a.shard.size()) || o.shards < 1 || o.shards > 1000000 || o.shard < 0 ||
        o.shard >= o.shards)
      throw ArgumentError("--shard: expected i/N with whole numbers 0 ≤ i < N ≤ 1000000, got '" + a.shard + "'");
  }
  if (a.vary.empty()) throw ArgumentError("--vary: give at least one key=a:b:n");
  for (const auto& v : a.vary) o.axes.push_back(parse_sweep_axis(v));
  return o;
}

int run_sweep_command(const SweepArgs& a) {
  if (!a.merge.empty()) return run_sweep_merge(a);
  if (a.inputs.size() != 1)
    throw ArgumentError(fmt::format("sweep: give one scene (got {}); several files are for --merge OUT.csv PART...",
                                    a.inputs.size()));
  if (a.out.empty()) throw ArgumentError("--out: give the output CSV file");
  const SweepOptions o = check_sweep_args(a);
  const std::string what = "sweep shard " + a.shard;
  const SweepPlan plan = plan_sweep(o);
  // Only a file can hold a finished part: a device or FIFO at --out (/dev/stdout) is written.
  if (a.resume && std::filesystem::is_regular_file(a.out)) {
    SweepPart part;
    const std::string why = why_not_complete(a.out, plan, part);
    if (why.empty())
      return report_sweep(what, fmt::format("{} cases already complete: skipped", plan.range.end - plan.range.first),
                          part.failed, a.out);
    std::fprintf(stderr, "rdyn: %s: running it again: %s\n", what.c_str(), why.c_str());
  }
  OutputFile out(a.out, a.force, is_rdyn_sweep);  // fails early on an unusable destination
  StderrProgress progress(what, plan.range.end - plan.range.first, Progress().enabled());
  const SweepResult r = run_sweep(plan, &progress);
  out.write(r.csv);
  out.commit();
  const double rate = r.elapsed_s > 0 ? static_cast<double>(r.cases) / r.elapsed_s : 0.0;
  return report_sweep(
      what,
      fmt::format("{} cases in {:.3g} s ({:.3g} cases/s, {} threads, {} tables)", r.cases, r.elapsed_s, rate, r.threads,
                  r.tables),
      r.failed, a.out);
}


int run_export_mjcf(const ExportMjcfArgs& a) {
  require_in("--timestep", a.timestep_s, cli_limits::kMinFixedStep_s, cli_limits::kMaxFixedStep_s, " s");
  const models::Scene scene = load(a.scene, a.sets);
  OutputFile out(a.out, a.force, is_rdyn_mjcf);  // fails early on an unusable destination
  models::MjcfOptions opt;
  opt.reference_q = calc_initial_joint_state(scene).q;  // loops closed where MJCF infers its anchors
  opt.fold_geared_bodies = a.fold;
  opt.timestep_s = a.timestep_s;
  opt.integrator = a.integrator;
  out.write(models::export_mjcf(scene, opt));
  out.commit();
  return 0;
}

models::Scene reduced_output_scene(const models::Scene& scene, nlohmann::json& run) {
  if (!scene.outputs.reactions_all) return scene;
  auto split = reduced::split_reduced_reactions(scene);
  if (!split.not_given.empty()) {
    // Said once: the grid check's runs start from a run.json that already says it.
    const bool said = run.contains("reactions_not_given");
    auto ng = nlohmann::json::array();
    for (const auto& [name, why] : split.not_given) {
      if (!said)
        std::fprintf(stderr,
                     "rdyn: warning: the reduced model does not give reaction '%s' (run --model full for it): %s\n",
                     name.c_str(), why.c_str());
      ng.push_back({{"reaction", name}, {"why", why}});
    }
    run["reactions_not_given"] = ng;
  }
  return std::move(split.scene);
}

}  // namespace rdyn::validate
