#include "validate/harness/harness.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include <fmt/format.h>

#include "engine/forward_dynamics.hpp"
#include "engine/independent_range.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/harness/ladder_plan.hpp"
#include "validate/harness/pareto.hpp"
#include "validate/harness/peers.hpp"
#include "validate/harness/thresholds.hpp"
#include "validate/harness/grid_check.hpp"
#include "validate/harness/timing.hpp"

namespace rdyn::validate {

namespace {

// The scene whose joint outputs the reduced runs give: the requested reactions it can give (the
// others are compared on the full model alone; ValidationResult::reactions_not_given).
models::Scene reduced_outputs_scene(const models::Scene& scene) {
  return reduced::split_reduced_reactions(scene).scene;
}


// A reduced run of that model as the user gets it: the joint outputs the scene asks for, from
// the table, and the internal lines removed again (what `rdyn simulate --model reduced` writes).
models::TimeSeries with_joint_outputs(const models::Scene& scene, const reduced::ReducedModel& model,
                                      models::TimeSeries ts) {
  if (reduced::wants_joint_outputs(scene)) reduced::add_joint_outputs(reduced_outputs_scene(scene), model, ts);
  return ts;
}


using Clock = std::chrono::steady_clock;

// Fewest steady revolutions over which a cycling run's errors are claimed: one revolution
// cannot show that the cycle repeats (detect_steady_window compares consecutive means).
constexpr int kMinSteadyRevolutions = 2;

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

void fill_stats(RunRecord& r, const models::TimeSeries& ts) {
  r.cycles = std::abs(ts.q.back() - ts.q.front()) / (2 * M_PI);
  const double end_residual = std::abs(ts.energy.back() - ts.energy.front() - ts.work.back());
  r.energy_drift_per_cycle_J = r.cycles >= 1 ? end_residual / r.cycles : end_residual;
  r.steps = ts.stats.steps_taken;
  r.rejected = std::max(0L, ts.stats.steps_attempted - ts.stats.steps_taken);
  r.smallest_step_s = ts.stats.smallest_step_s;
  r.constraint_violation_m = ts.stats.max_constraint_error;
  r.events = ts.stats.events;
}

// |E − E0 − W| relative to the energy scale (models::energy_balance: one implementation).
double energy_residual_rel(const models::TimeSeries& ts) {
  const auto b = models::energy_balance(ts);
  return b.energy_scale_J > 0 ? b.max_residual_J / b.energy_scale_J : b.max_residual_J;
}

// A ladder run that stopped (a budget, an energy balance that does not close, divergence,
// the validity domain) is recorded with its reason instead of ending the validation.
void record_stopped(RunRecord& r, const std::string& why, ValidationResult& v) {
  mark_stopped(r, why, v.quantities);
  v.runs.push_back(r);
}

std::string machine_description() {
  std::string cpu = "unknown CPU";
  std::ifstream f("/proc/cpuinfo");
  for (std::string line; std::getline(f, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  std::string os;
  std::ifstream r("/etc/os-release");
  for (std::string line; std::getline(r, line);)
    if (line.rfind("PRETTY_NAME=", 0) == 0) os = line.substr(13, line.size() - 14);
  return fmt::format("{}, {} hardware threads{}", cpu, std::thread::hardware_concurrency(),
                     os.empty() ? "" : ", " + os);
}

}  // namespace

models::Scene extraction_scene(const models::Scene& scene) {
  return reduced::wants_joint_outputs(scene) ? reduced::with_reaction_requests(reduced_outputs_scene(scene)) : scene;
}

void finish_run(RunRecord& r, const std::vector<double>& walls, const models::TimeSeries& ts,
                const ValidationResult& v) {
  r.repeats = static_cast<int>(walls.size());
  r.wall_s = median(walls);
  r.per_simulated_s = r.wall_s / v.duration_s;
  fill_stats(r, ts);
  r.energy_residual_rel = energy_residual_rel(ts);
  r.errors = compare_series(v.reference, ts, v.window.t_start);
}

void mark_stopped(RunRecord& r, const std::string& why, const std::vector<std::string>& quantities) {
  r.failure = why;
  for (const auto& q : quantities) r.errors.signals.push_back({q, 0.0, INFINITY, INFINITY});
  r.repeats = 0;
  r.wall_s = r.per_simulated_s = INFINITY;
}

double RunRecord::error_of(const std::string& q) const {
  const SignalError* s = errors.find(q);
  return s && std::isfinite(s->max_rel) ? s->max_rel : INFINITY;
}

std::string RunRecord::label() const {
  if (model == "full") return fmt::format("full {} tol {:.0e}", integrator, tolerance);
  if (model != "reduced") return fmt::format("{} {} h={:.3g} ms", model, integrator, fixed_step_s * 1e3);
  std::string s = fmt::format("reduced {:g}° {}{}", grid_deg, fit.empty() ? interpolation : fit,
                              energy_consistent ? "+ec" : "");
  if (integrator == "rk4-fixed") return s + fmt::format(" rk4 h={:g} ms", fixed_step_s * 1e3);
  return s + fmt::format(" {} tol {:.0e}", integrator, tolerance);
}

namespace {

// The domain is computed once per model, outside the timed runs.
engine::ForwardOptions forward_options(const ValidationResult& v, const std::string& integrator, double tol,
                                       const engine::IndependentDomain& domain) {
  engine::ForwardOptions fo;
  fo.domain = domain;
  fo.duration_s = v.duration_s;
  fo.output_interval_s = v.output_interval_s;
  fo.tolerance = tol;
  fo.integrator = integrator;
  return fo;
}

reduced::ReducedOptions reduced_options(const ValidationResult& v, const std::string& integrator, double tol,
                                        double h) {
  reduced::ReducedOptions ro;
  ro.duration_s = v.duration_s;
  ro.output_interval_s = v.output_interval_s;
  ro.tolerance = tol;
  ro.integrator = integrator;
  ro.fixed_step_s = h;
  return ro;
}

// What is validated, from the scene alone.
ValidationResult describe(const models::Scene& scene) {
  ValidationResult v;
  v.scene = scene.name;
  v.scene_file = scene.source_file;
  v.note = scene.validation.note;
  v.compare = scene.validation.compare;
  v.machine = machine_description();
  v.duration_s = scene.validation.duration_s > 0 ? scene.validation.duration_s : scene.simulation.duration_s;
  v.output_interval_s = scene.simulation.output_interval_s;
  // Runs are compared row by row, and the MuJoCo peer fills every output interval with whole
  // steps: validation spans whole output intervals (the rows up to the duration, as every run
  // ended before `simulate` wrote a last row at the duration itself).
  const double whole = std::floor(v.duration_s / v.output_interval_s + 1e-9);
  if (whole >= 1) v.duration_s = std::min(v.duration_s, whole * v.output_interval_s);
  v.headline_quantity = scene.outputs.constraint_forces.empty() ? "qdot" : scene.outputs.constraint_forces[0].name;
  v.quantities = {"qdot"};
  for (const auto& c : scene.outputs.constraint_forces) v.quantities.push_back(c.name);
  // The joint outputs both models give are judged like the constraint forces; a reaction only the
  // full model gives is plotted from it and named (reduced::split_reduced_reactions).
  if (reduced::wants_joint_outputs(scene)) {
    auto split = reduced::split_reduced_reactions(scene);
    v.joint_output_quantities = models::joint_output_names(split.scene);
    for (const auto& n : v.joint_output_quantities) v.quantities.push_back(n);
    // A threshold judges the reduced model against the full one: on a column only the full model
    // gives it could only fail, after the whole ladder. Refused before any work.
    const auto all_columns = models::joint_output_names(scene);
    for (size_t i = 0; i < scene.validation.thresholds.size(); ++i) {
      const std::string& q = scene.validation.thresholds[i].quantity;
      const bool full_only =
          std::find(all_columns.begin(), all_columns.end(), q) != all_columns.end() &&
          std::find(v.joint_output_quantities.begin(), v.joint_output_quantities.end(), q) ==
              v.joint_output_quantities.end();
      if (!full_only) continue;
      const std::string field = fmt::format("validation.thresholds[{}].quantity", i);
      int line = scene.line_of(field);
      for (const std::string& key : {fmt::format("validation.thresholds[{}]", i), std::string("validation.thresholds")})
        if (line == 0) line = scene.line_of(key);
      throw models::SceneError(scene.source_file, line, field,
                               fmt::format("'{}' is a column the reduced model does not give ({}); a threshold "
                                           "compares the two models",
                                           q, split.not_given.empty() ? std::string("see outputs.reactions")
                                                                      : split.not_given.front().second));
    }
    v.reactions_not_given = std::move(split.not_given);
  }
  v.quantities.push_back("mean_qdot");
  v.reference_tolerance = scene.validation.reference_tolerance;
  return v;
}

// Stage 2: the full-model tolerance ladder, each run timed by repeats.
void run_full_ladder(const std::string& name, engine::FullModel& full, const LadderPlan& plan, ValidationResult& v,
                     Progress& progress) {
  const long n = static_cast<long>(plan.full.size());
  const auto domain = engine::calc_independent_domain(full);
  for (long i = 0; i < n; ++i) {
    progress.count(name + ": full-model tolerance ladder", i, n);
    RunRecord r;
    r.model = "full";
    r.integrator = plan.full[i].first;
    r.tolerance = plan.full[i].second;
    models::TimeSeries ts;
    const auto fo = forward_options(v, r.integrator, r.tolerance, domain);
    std::vector<double> walls;
    try {
      if (plan.time_full_without_outputs) {
        // Fair baseline (issue #11): Simbody interpolates outputs but still ends a step at each
        // output time (5 ms outputs: 1020 steps over the bicycle's 5 s at 1e-4…1e-6 alike, 264–451
        // with one output), so the timed repeats write one output at the end; the errors come
        // from one run of the same settings on the output grid.
        ts = engine::simulate_full(full, fo);  // checked: the branch guard at every output
        auto fo_timed = fo;
        fo_timed.output_interval_s = v.duration_s;
        fo_timed.branch_guard = false;  // the same motion, already checked: Simbody's cost alone
        models::TimeSeries timed;
        walls = time_repeats([&] { timed = engine::simulate_full(full, fo_timed); }, plan.full_repeats);
        r.timed_output_interval_s = fo_timed.output_interval_s;
        r.timed_steps = timed.stats.steps_taken;
      } else {
        ts = engine::simulate_full(full, fo);  // checked: the branch guard at every output
        auto fo_timed = fo;
        fo_timed.branch_guard = false;  // the same motion, already checked: Simbody's cost alone
        walls = time_repeats([&] { engine::simulate_full(full, fo_timed); }, plan.full_repeats);
        r.timed_steps = ts.stats.steps_taken;
      }
    } catch (const models::NumericalError& e) {
      record_stopped(r, e.what(), v);
      continue;
    }
    finish_run(r, walls, ts, v);
    v.runs.push_back(r);
  }
  progress.count(name + ": full-model tolerance ladder", n, n);
}

// Stage 3: the reduced ladder, grid × interpolation (× energy-consistent m2) × integrator. A run
// that stops (divergence, validity domain) is recorded with its reason.
void run_reduced_ladder(const models::Scene& scene, const LadderPlan& plan, ValidationResult& v, Progress& progress) {
  long done = 0;
  const long total = plan.reduced_runs();
  for (double grid : plan.grids_deg) {
    Extraction e;
    std::vector<double> ms, build_ms, assembly_ms, kinetostatics_ms;
    for (int k = 0; k < (grid == 10 ? plan.extraction_repeats_10deg : 1); ++k) {
      e = extract_from_full(extraction_scene(scene), grid, reduced::Method::Kinetostatic, /*require_closed_turn=*/false);
      ms.push_back(e.extraction_ms);
      build_ms.push_back(e.stages.system_build_ms);
      assembly_ms.push_back(e.stages.assembly_ms);
      kinetostatics_ms.push_back(e.stages.kinetostatics_ms);
    }
    v.extractions.push_back({grid, median(ms), e.calls, static_cast<int>(e.samples.q.size())});
    if (grid == 10) {
      v.extraction_ms = median(ms);
      v.extraction_stages = {median(build_ms), median(assembly_ms), median(kinetostatics_ms)};
      v.samples10 = e.samples;
    }
    for (const auto& var : plan.variants) {
      // A table whose interpolant is not a model (m1 ≤ 0 between coarse grid points of a crank
      // that folds flat) stops that variant's runs, recorded with the reason: the scene's
      // validation exited 2 at its 30° grid.
      std::optional<reduced::ReducedModel> built;
      std::string not_a_model;
      try {
        built = reduced::make_reduced_model(e.samples, extraction_scene(scene),
                                            reduced::parse_interpolation(var.interpolation), var.energy_consistent);
      } catch (const reduced::TableError& err) {
        not_a_model = err.what();
      }
      auto add_run = [&](const std::string& integrator, double tol, double h) {
        progress.count(scene.name + ": reduced ladder", done++, total);
        RunRecord r;
        r.model = "reduced";
        r.grid_deg = grid;
        r.interpolation = var.interpolation;
        r.energy_consistent = var.energy_consistent;
        r.integrator = integrator;
        r.tolerance = tol;
        r.fixed_step_s = h;
        if (!built) {
          record_stopped(r, not_a_model, v);
          return;
        }
        const reduced::ReducedModel& model = *built;
        r.fit = model.table.fit;
        auto ro = reduced_options(v, integrator, tol, h);
        models::TimeSeries timed, rows, ts;
        std::vector<double> walls;
        try {
          // Timed like the full model (plan.time_reduced_without_outputs: one output at the end;
          // the steps do not depend on the outputs); compared on rows as accurate as the steps
          // (one extra single step per row, untimed), so the errors are the model's and the
          // integrator's; the Hermite rows a user gets between steps are measured apart
          // (output_interpolation).
          auto ro_timed = ro;
          if (plan.time_reduced_without_outputs) ro_timed.output_interval_s = v.duration_s;
          walls = time_repeats(
              [&] { timed = reduced::simulate_reduced(model, scene.initial.q, scene.initial.qdot, ro_timed); },
              plan.reduced_repeats);
          r.timed_output_interval_s = ro_timed.output_interval_s;
          r.timed_steps = timed.stats.steps_taken;
          rows = with_joint_outputs(scene, model,
                                    plan.time_reduced_without_outputs
                                        ? reduced::simulate_reduced(model, scene.initial.q, scene.initial.qdot, ro)
                                        : timed);
          ro.step_outputs = true;
          ts = with_joint_outputs(scene, model, reduced::simulate_reduced(model, scene.initial.q, scene.initial.qdot, ro));
        } catch (const std::runtime_error& e) {  // TableError (validity domain) or NumericalError
          record_stopped(r, e.what(), v);
          return;
        }
        finish_run(r, walls, ts, v);
        r.compared_run_wall_s = ts.stats.wall_time_s;
        r.output_interpolation = compare_series(ts, rows, v.window.t_start);
        v.runs.push_back(r);
        if (std::abs(grid - v.default_grid_deg) < 1e-9 && var.interpolation == kDefaultInterpolation &&
            !var.energy_consistent && integrator == "rk8pd" && tol == plan.tightest_tolerance()) {
          v.showcase = ts;
          v.showcase_run = static_cast<int>(v.runs.size()) - 1;
        }
      };
      for (double tol : plan.rk8pd_tolerances) add_run("rk8pd", tol, 0.0);
      if (plan.rkck) add_run("rkck", 1e-8, 0.0);
      // Fixed-step RK4, the real-time stepper (outputs by dense interpolation).
      for (double h : plan.fixed_steps_s) add_run("rk4-fixed", 0.0, h);
    }
  }
  progress.count(scene.name + ": reduced ladder", total, total);
}

// The interpolant of the 10° table at 1° (figure 1).
void calc_dense_params(const models::Scene& scene, ValidationResult& v) {
  if (v.samples10.q.empty()) return;
  std::optional<reduced::ReducedModel> built;
  try {
    built = reduced::make_reduced_model(v.samples10, extraction_scene(scene), reduced::Interpolation::Fourier);
  } catch (const reduced::TableError&) {
    return;  // not a model at 10° (its ladder runs say why): no figure
  }
  const auto& m = *built;
  std::vector<int> cols{m.c_m1, m.c_m2};
  v.dense_names = {"q_deg", "m1", "m2"};
  for (size_t k = 0; k < scene.outputs.constraint_forces.size(); ++k) {  // not the internal lines
    cols.push_back(m.c_me1[k]);
    cols.push_back(m.c_me2[k]);
    v.dense_names.push_back("me1_" + m.force_names[k]);
    v.dense_names.push_back("me2_" + m.force_names[k]);
  }
  v.dense_params.assign(cols.size() + 1, {});
  // A range table: 360 equal steps over its range (deg or m), not a turn.
  const bool range = !v.samples10.periodic;
  const double span = range ? v.samples10.q.back() - v.samples10.q0 : 2 * M_PI;
  const double unit = v.samples10.revolute ? 180 / M_PI : 1.0;
  if (!v.samples10.revolute) v.dense_names[0] = "q_m";
  for (int d = 0; d <= 360; ++d) {
    const double q = v.samples10.q0 + d * span / 360;
    v.dense_params[0].push_back(q * unit);
    for (size_t c = 0; c < cols.size(); ++c) v.dense_params[c + 1].push_back(m.table.eval(cols[c], q));
  }
}

// Stage 6: the scene's thresholds; a grid outside the ladder is run now.
void judge_thresholds(const models::Scene& scene, ValidationResult& v) {
  v.default_thresholds = scene.validation.thresholds.empty();
  for (const auto& th : thresholds_of(scene, v.quantities, v.default_grid_deg)) {
    // A reference that moves by more than a threshold when its tolerance is halved cannot
    // judge that threshold: the error measured would be the reference's own (a chain through
    // its flat configuration passed with a reference whose q̇ changed by 100 % of its peak).
    if (const SignalError* ch = v.reference_change.find(th.quantity); ch && !(ch->max_rel <= th.max_error))
      v.fail(fmt::format("the reference does not converge: halving its tolerance changes {} by {:.3g} of its peak, "
                         "more than the threshold {:.3g} it must judge (tighten validation.reference_tolerance or "
                         "choose another validation.reference_integrator)",
                         th.quantity, ch->max_rel, th.max_error));
    auto tr = judge_threshold(th, v.runs, v.tightest_tolerance);
    if (!tr) {
      const std::string interp = th.interpolation.empty() ? kDefaultInterpolation : th.interpolation;
      const auto e =
          extract_from_full(extraction_scene(scene), th.grid_deg, reduced::Method::Kinetostatic, /*require_closed_turn=*/false);
      RunRecord r;
      r.model = "reduced";
      r.grid_deg = th.grid_deg;
      r.interpolation = interp;
      r.integrator = "rk8pd";
      r.tolerance = v.tightest_tolerance;
      try {  // a table that is not a model, a run that stops: the threshold fails, saying why
        const auto m =
            reduced::make_reduced_model(e.samples, extraction_scene(scene), reduced::parse_interpolation(interp));
        r.fit = m.table.fit;
        auto ro = reduced_options(v, "rk8pd", v.tightest_tolerance, 0.0);
        ro.step_outputs = true;  // compared rows as accurate as the steps, as in the ladder
        const auto ts = with_joint_outputs(scene, m, reduced::simulate_reduced(m, scene.initial.q, scene.initial.qdot, ro));
        r.errors = compare_series(v.reference, ts, v.window.t_start);
      } catch (const std::runtime_error& err) {  // TableError (validity domain) or NumericalError
        mark_stopped(r, err.what(), v.quantities);
      }
      tr = judge_threshold_on(th, r);
    }
    if (!tr->pass)
      v.fail(fmt::format("threshold {} at {:g}°: error {:.3g} exceeds {:.3g} ({})", th.quantity, th.grid_deg, tr->error,
                         th.max_error, tr->run));
    v.thresholds.push_back(*tr);
  }
}

}  // namespace

// A table whose full-turn sweep does not close at any grid keeps 10°: the ladder
// (require_closed_turn off) records what each grid gives. The grid is then checked as `rdyn
// simulate` checks it (validate/harness/grid_check.hpp): the scene's run with the default
// settings against the run on half the grid.
DefaultTable calc_default_table(const models::Scene& scene) {
  DefaultTable d;
  const models::Scene xscene = extraction_scene(scene);
  try {
    d.samples = extract_resolving(xscene, kDefaultThresholdGrid_deg, /*grid_given=*/false,
                                  reduced::Method::Kinetostatic, d.grid_deg)
                    .samples;
  } catch (const reduced::SweepNotClosed&) {
    return {};
  }
  struct GridRun {
    reduced::Samples samples;
    models::TimeSeries ts;
  };
  reduced::ReducedOptions ro;  // simulate's defaults (rk8pd at 1e-8) over the scene's run
  ro.duration_s = scene.simulation.duration_s;
  ro.output_interval_s = scene.simulation.output_interval_s;
  auto run_on = [&](const reduced::Samples& samples) {
    const auto m = reduced::make_reduced_model(samples, xscene, reduced::Interpolation::Fourier);
    GridRun r{samples, {}};
    r.ts = with_joint_outputs(scene, m, reduced::simulate_reduced(m, scene.initial.q, scene.initial.qdot, ro));
    return r;
  };
  GridRun kept;
  try {
    kept = run_on(d.samples);
  } catch (const std::runtime_error& e) {  // not a model, or its run fails: the ladder says why
    d.check.grid_deg = d.grid_deg;
    d.check.not_compared = e.what();
    return d;
  }
  kept = check_grid_by_runs(
      std::move(kept), d.grid_deg,
      [&](double g) { return run_on(extract_from_full(xscene, g, reduced::Method::Kinetostatic).samples); }, false,
      d.check);
  d.grid_deg = d.check.grid_deg;
  d.samples = std::move(kept.samples);
  return d;
}

void run_reference(const models::Scene& scene, engine::FullModel& full, ValidationResult& v, Progress& progress) {
  // A coordinate confined to a range (a rocker, a slider) has no revolutions to count.
  const auto domain = engine::calc_independent_domain(full);
  const bool rotating = scene.find_joint(scene.independent)->type == models::JointType::Revolute && domain.periodic;
  const std::string integrator = scene.validation.reference_integrator;
  progress.count(scene.name + ": reference (full model)", 0, 2);
  const auto t_ref = Clock::now();
  v.reference = engine::simulate_full(full, forward_options(v, integrator, v.reference_tolerance, domain));
  v.reference_wall_s = seconds_since(t_ref);
  v.reference_run.model = "full";
  v.reference_run.integrator = integrator;
  v.reference_run.tolerance = v.reference_tolerance;
  v.reference_run.wall_s = v.reference_wall_s;
  v.reference_run.per_simulated_s = v.reference_wall_s / v.duration_s;
  v.reference_run.repeats = 1;
  fill_stats(v.reference_run, v.reference);
  v.reference_run.energy_residual_rel = energy_residual_rel(v.reference);
  progress.count(scene.name + ": reference (full model)", 1, 2);
  const auto half = engine::simulate_full(full, forward_options(v, integrator, v.reference_tolerance / 2, domain));
  progress.count(scene.name + ": reference (full model)", 2, 2);
  v.window = detect_steady_window(v.reference, rotating);
  v.reference_change = compare_series(v.reference, half, v.window.t_start);
  // Errors and speedups are claimed only over enough samples (issue #9).
  if (v.reference_change.samples < kMinComparedSamples)
    v.fail(fmt::format("only {} output samples in the compared window ({}); at least {} are needed to claim an error: "
                       "lengthen validation.duration_s or shorten simulation.output_interval_s",
                       v.reference_change.samples, v.window.how, kMinComparedSamples));
  if (const SignalError* speed = v.reference_change.find("qdot"); speed && !(speed->peak > 0))
    v.fail("the mechanism does not move in the reference run (its speed is 0 throughout): there is nothing to "
           "compare");
  if (!v.window.whole_run && v.window.revolutions < kMinSteadyRevolutions)
    v.fail(fmt::format("the run never settles into a steady cycle: only {} revolution(s) after the start-up transient "
                       "({}); lengthen validation.duration_s",
                       v.window.revolutions, v.window.how));
  v.time_scale = calc_time_scale(v.reference, rotating);
}

void analyse_runs(ValidationResult& v) {
  mark_pareto(v.runs, v.headline_quantity);
  const auto matched = calc_matched_speedup(v.runs, v.headline_quantity, v.matched_target);
  v.matched_full = matched.full;
  v.matched_reduced = matched.reduced;
  v.speedup_at_matched_error.reset();
  // No claim from too few samples or a validation that already failed.
  if (v.failures.empty() && v.reference_change.samples >= kMinComparedSamples) v.speedup_at_matched_error = matched.speedup;
  // Every judged quantity within the target (so the first screen's verdicts are all met); when no
  // run reaches that, the speed and the headline alone, its misses shown in the verdicts. The
  // status stays the thresholds' (on the defaults: 0.5 % on every quantity at the default grid):
  // a --quick ladder stops at 5°, where a Whitworth's reactions were within 0.17 %.
  v.recommended = pick_recommended(v.runs, v.quantities, v.matched_target);
  v.recommended_on_all = v.recommended >= 0;
  if (v.recommended < 0) v.recommended = pick_recommended(v.runs, {"qdot", v.headline_quantity}, v.matched_target);
  const SignalError* ref = v.reference_change.find(v.headline_quantity);
  v.convergence_floor = 10 * std::max(1e-12, ref ? ref->max_rel : 0.0);
  v.convergence = calc_convergence(v.runs, v.headline_quantity, v.tightest_tolerance, v.convergence_floor);
  analyse_peers(v);
}

void calc_drive_cycle(const models::Scene& scene, ValidationResult& v) {
  const double cadence = scene.validation.calibrate_cadence_Hz;
  const bool revolute = scene.find_joint(scene.independent)->type == models::JointType::Revolute;
  if (!(cadence > 0) || !revolute || v.samples10.q.empty() || !v.samples10.periodic) return;
  // On the table `rdyn drive --cadence-hz` takes (the default grid, already extracted): a five-bar
  // geared 6:1 was drawn 25 % off on the 10° one while the command the report names agreed to 2e-7.
  const reduced::Samples& samples = v.default_grid_deg == 10.0 ? v.samples10 : v.default_samples;
  if (samples.q.empty() || !samples.periodic) return;
  const auto model = reduced::make_reduced_model(samples, extraction_scene(scene), reduced::Interpolation::Fourier);
  v.drive_cycle = calc_drive_cycle_comparison(scene, model, cadence);
  v.drive_cycle->grid_deg = v.default_grid_deg;
}

void calc_first_screen(ValidationResult& v) {
  // A scene judged on the defaults must also reach the validation's own target: a reduced
  // setting within it on the speed and the headline quantity; none is a failure, not a pass with
  // nothing recommended. Declared thresholds are the scene's own verdict (the hard high-saddle
  // accepts 0.5 on its knee force).
  if (v.recommended < 0 && v.default_thresholds)
    v.fail(fmt::format("no reduced run reached the error target {:.3g} on qdot and {} (refine the grid or check the "
                       "reference)",
                       v.matched_target, v.headline_quantity));
  const RunRecord* rec = v.recommended >= 0 ? &v.runs[v.recommended] : nullptr;
  v.verdicts = calc_verdicts(v.quantities, rec, v.matched_target);
  v.baselines.clear();
  v.budget.reset();
  v.recommended_full = -1;
  v.recommended_full_as_accurate = true;
  v.recommended_speedup.reset();
  if (!rec) return;
  // One setting on the first screen: its errors, and its speed against the cheapest full run at
  // least as accurate on the quantities it was chosen on (so within the target on them too: a
  // threshold failing on another grid does not make this comparison less true; the status says it).
  const std::vector<std::string> chosen_on{"qdot", v.headline_quantity};
  v.recommended_full = pick_matched_full(*rec, v.runs, chosen_on);
  if (v.recommended_full < 0) {
    // No ladder run as accurate (a --quick ladder, a very fine table): the reference's ratio
    // would flatter the reduced model by the reference's extra accuracy (coarse-grid: 2.3e4×
    // against ~3e3× at equal error); its floor, the most accurate ladder run, does not.
    v.recommended_full = pick_most_accurate_full(*rec, v.runs, chosen_on);
    v.recommended_full_as_accurate = v.recommended_full < 0;
  }
  const RunRecord& against = v.recommended_full >= 0 ? v.runs[v.recommended_full] : v.reference_run;
  if (v.reference_change.samples >= kMinComparedSamples && rec->wall_s > 0 &&
      std::isfinite(against.wall_s))
    v.recommended_speedup = against.wall_s / rec->wall_s;
  v.baselines = calc_baselines(*rec, v.reference_run, v.runs, v.recommended_full, v.recommended_full_as_accurate);
  const SignalError* ref = v.reference_change.find(v.headline_quantity);
  v.budget = calc_error_budget(*rec, v.runs, ref ? ref->max_rel : NAN, v.headline_quantity, v.tightest_tolerance);
}

namespace {

// A numerical failure after the reference ran is a finding of the validation, not its end: the
// stage is recorded as failed and the report is still written (README, exit codes: "validate
// still writes its report"). A leg press whose calibration missed exited 1 after 66 s with
// nothing written. Bad input (scene, table, engine errors) still stops at once.
template <class Stage>
void run_stage(ValidationResult& v, const char* what, Stage&& stage) {
  try {
    stage();
  } catch (const models::NumericalError& e) {
    // A message that already starts with the stage's name (calibrate's do) is not prefixed again.
    const std::string msg = e.what(), prefix = std::string(what) + ": ";
    v.fail(msg.rfind(prefix, 0) == 0 ? msg : prefix + msg);
  }
}

}  // namespace

ValidationResult run_validation(const models::Scene& scene, const ValidationOptions& opt, Progress& progress) {
  ValidationResult v = describe(scene);
  // The scene's operating point is checked before any work (the calibration itself runs last):
  // an unknown load or a scene that cannot be calibrated is bad input, refused at once.
  if (scene.validation.calibrate_cadence_Hz > 0)
    check_calibratable(scene, calibration_options_of(scene, 0.0, 0.0, ""));
  // 1. Reference: full model at a tight tolerance, and the change when it is halved; the
  //    scene's time scale from it sets the fixed steps of the ladder.
  engine::FullModel full(scene);
  run_reference(scene, full, v, progress);
  const LadderPlan plan = plan_ladders(v.time_scale, opt.quick);
  v.fixed_steps = plan.fixed_steps_s;
  v.tightest_tolerance = plan.tightest_tolerance();
  v.full_timing = plan.time_full_without_outputs
                      ? fmt::format("Full-model runs are timed with one output at the end of the {:g} s run, so the "
                                    "output grid never caps Simbody's step (errors from the same settings on the {:g} s "
                                    "output grid); each integrator (RK-Merson, RK3, CPodes) over a tolerance ladder, the "
                                    "cheapest within the error target is the baseline.{}",
                                    v.duration_s, v.output_interval_s,
                                    plan.time_reduced_without_outputs && plan.time_peers_without_outputs
                                        ? " The reduced model and the peer engines are timed the same way (one "
                                          "output at the end; their steps do not depend on the outputs), their errors "
                                          "also read on the output grid."
                                        : "")
                      : "Full-model runs are timed on the output grid.";
  // 2–3. The ladders.
  run_stage(v, "full-model ladder", [&] { run_full_ladder(scene.name, full, plan, v, progress); });
  run_stage(v, "reduced ladder", [&] {
    auto d = calc_default_table(scene);
    v.default_grid_deg = d.grid_deg;
    v.default_grid_check = d.check;
    if (d.grid_deg != 10.0) v.default_samples = std::move(d.samples);
    run_reduced_ladder(scene, with_grid(plan, v.default_grid_deg), v, progress);
    calc_dense_params(scene, v);
  });
  // 3b. Peer engines (MuJoCo) on the same scene, timed like the full model.
  v.peer_steps = plan.peer_steps_s;
  if (!opt.peers.empty()) run_stage(v, "peer ladders", [&] { run_peer_ladders(scene, opt.peers, plan, v, progress); });
  // 4. Pareto front, matched-error speedup, recommended setting, convergence.
  analyse_runs(v);
  // 5. Calibration (scenes that declare an operating point).
  if (scene.validation.calibrate_cadence_Hz > 0) {
    v.calibration_options = calibration_options_of(scene, 0.0, 0.0, "");
    progress.note(scene.name + ": calibrating the drive load");
    run_stage(v, "calibration", [&] { v.calibration = calibrate(scene, v.calibration_options, progress); });
    // Both models at the calibrated operating point (the report's calibration figure).
    if (v.calibration)
      run_stage(v, "calibrated operating point", [&] {
        v.calibrated_run =
            calc_calibrated_run(scene, v.calibration_options, *v.calibration, v.samples10, v.output_interval_s);
      });
  }
  // 5b. The drive over one revolution at that cadence from both models (the report's figure).
  run_stage(v, "drive cycle", [&] { calc_drive_cycle(scene, v); });
  // 6–7. Thresholds, then the first screen: verdicts, baselines, error budget.
  run_stage(v, "thresholds", [&] { judge_thresholds(scene, v); });
  calc_first_screen(v);
  return v;
}

std::string ValidationResult::failure_summary() const {
  std::string s;
  for (const auto& f : failures) s += (s.empty() ? "" : "; ") + f;
  return s;
}

}  // namespace rdyn::validate
