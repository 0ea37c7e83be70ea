#include "validate/cli/drive_command.hpp"

#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "models/scene_yaml.hpp"
#include "reduced/samples.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/cli/commands.hpp"
#include "validate/cli/cli_limits.hpp"
#include "validate/analysis/drive.hpp"
#include "validate/harness/grid_check.hpp"
#include "validate/cli/decimal_number.hpp"
#include "validate/io/output_dir.hpp"

namespace rdyn::validate {

namespace {

// The output rows: every k-th row of the fine record and its last (the duration itself).
DriveRecord every_kth_row(const DriveRecord& r, long k) {
  if (k == 1) return r;
  DriveRecord o;
  o.force_names = r.force_names;
  o.forces.assign(r.forces.size(), {});
  o.column_names = r.column_names;
  o.columns.assign(r.columns.size(), {});
  for (size_t i = 0; i < r.t.size(); ++i) {
    if (i % static_cast<size_t>(k) != 0 && i + 1 != r.t.size()) continue;
    o.t.push_back(r.t[i]), o.q.push_back(r.q[i]), o.qdot.push_back(r.qdot[i]), o.qddot.push_back(r.qddot[i]);
    o.drive.push_back(r.drive[i]), o.power.push_back(r.power[i]);
    for (size_t c = 0; c < r.forces.size(); ++c) o.forces[c].push_back(r.forces[c][i]);
    for (size_t c = 0; c < r.columns.size(); ++c) o.columns[c].push_back(r.columns[c][i]);
  }
  return o;
}

void write_drive_csv(const std::string& path, const DriveRecord& r, bool revolute) {
  TextSink sink(path);
  std::string header;
  for (const auto& n : drive_column_names(r, revolute)) header += (header.empty() ? "" : ",") + n;
  sink.add(header + "\n");
  for (size_t i = 0; i < r.t.size(); ++i) {
    std::string row = fmt::format("{:.10g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", r.t[i], r.q[i], r.qdot[i],
                                  r.qddot[i], r.drive[i], r.power[i]);
    for (const auto& c : r.forces) row += fmt::format(",{:.17g}", c[i]);
    for (const auto& c : r.columns) row += fmt::format(",{:.17g}", c[i]);
    sink.add(row + "\n");
  }
  sink.close();
}

// An argument the scene cannot take: reported as the scene's error on the option (exit 2).
[[noreturn]] void refuse(const models::Scene& scene, const std::string& option, const std::string& msg) {
  throw models::SceneError(scene.source_file, 0, option, msg);
}

// Every number before any work: one motion (--cadence-hz or --profile), the duration, the output
// interval `dt` [s], the grid and the model.
void check_drive_arguments(const DriveArgs& a, const models::Scene& scene, bool revolute, double dt) {
  if (a.cadence_hz.has_value() == !a.profile.empty()) refuse(scene, "--cadence-hz", "give --cadence-hz or --profile (one of them)");
  if (a.cadence_hz) {
    if (!revolute) refuse(scene, "--cadence-hz", "a constant rate needs a revolute independent coordinate: give --profile");
    if (!(std::isfinite(*a.cadence_hz) && *a.cadence_hz != 0 && std::abs(*a.cadence_hz) <= cli_limits::kMaxCadence_Hz))
      refuse(scene, "--cadence-hz", fmt::format("must be a finite, non-zero rate with |F| ≤ {:g} rev/s (got {:g})",
                                                cli_limits::kMaxCadence_Hz, *a.cadence_hz));
  }
  if (a.duration && !(std::isfinite(*a.duration) && *a.duration > 0 && *a.duration <= cli_limits::kMaxDuration_s))
    refuse(scene, "--duration", fmt::format("must be in (0, {:g}] s (got {:g})", cli_limits::kMaxDuration_s, *a.duration));
  if (!(std::isfinite(dt) && dt >= cli_limits::kMinOutputInterval_s && dt <= cli_limits::kMaxDuration_s))
    refuse(scene, "--dt-out", fmt::format("must be in [{:g}, {:g}] s (got {:g})", cli_limits::kMinOutputInterval_s,
                                          cli_limits::kMaxDuration_s, dt));
  // The range simulate and extract accept (cli_limits), not a second one.
  if (!(a.grid_deg >= cli_limits::kMinGrid_deg && a.grid_deg <= cli_limits::kMaxGrid_deg) ||
      std::abs(360 / a.grid_deg - std::round(360 / a.grid_deg)) > 1e-9 * 360 / a.grid_deg)
    refuse(scene, "--grid-deg", fmt::format("must be in [{:g}, {:g}] deg and divide 360° into whole steps (got {:g})",
                                            cli_limits::kMinGrid_deg, cli_limits::kMaxGrid_deg, a.grid_deg));
  if (a.model != "full" && a.model != "reduced") refuse(scene, "--model", "full or reduced");
}

// --motor STALL,NO_LOAD in the scene's units for a motor (N·m and rad/s on a revolute
// coordinate, N and m/s on a prismatic one), one sign for both (docs/scene-format.md, motor).
std::optional<std::pair<double, double>> parse_motor_option(const DriveArgs& a, const models::Scene& scene,
                                                            bool revolute) {
  if (a.motor.empty()) return std::nullopt;
  const auto comma = a.motor.find(',');
  const std::string units = revolute ? "N·m,rad/s" : "N,m/s";
  if (comma == std::string::npos || a.motor.find(',', comma + 1) != std::string::npos)
    refuse(scene, "--motor", "give STALL,NO_LOAD (" + units + "), e.g. 40,12 (got '" + a.motor + "')");
  double v[2];
  for (int i = 0; i < 2; ++i) {
    const std::string part = i == 0 ? a.motor.substr(0, comma) : a.motor.substr(comma + 1);
    if (const auto why = check_decimal_number(part); !why.empty()) refuse(scene, "--motor", why + " in '" + a.motor + "'");
    v[i] = read_decimal_number(part);
  }
  if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && v[0] != 0 && v[1] != 0 && (v[0] > 0) == (v[1] > 0) &&
        std::abs(v[0]) <= cli_limits::kMaxMotorStall && std::abs(v[1]) <= cli_limits::kMaxMotorSpeed))
    refuse(scene, "--motor",
           fmt::format("stall and no-load speed must be non-zero, finite, of one sign (the speed the motor "
                       "drives toward), |stall| ≤ {:g} and |no-load speed| ≤ {:g} ({}; got {})",
                       cli_limits::kMaxMotorStall, cli_limits::kMaxMotorSpeed, units, a.motor));
  return std::make_pair(v[0], v[1]);
}

// The prescribed motion at time steps `step` [s], checked against the output interval `dt` [s].
PrescribedMotion calc_motion_at(const DriveArgs& a, const models::Scene& scene, bool revolute, double dt,
                                double step) {
  PrescribedMotion m;
  if (a.cadence_hz) {
    const double duration = a.duration.value_or(1.0 / std::abs(*a.cadence_hz));  // one revolution
    // Without --duration the run is one revolution, so its length is the cadence's: name it.
    const char* whose = a.duration ? "--duration" : "--cadence-hz";
    const std::string run = a.duration ? fmt::format("the {:g} s run", duration)
                                       : fmt::format("one revolution at {:g} rev/s ({:g} s)", *a.cadence_hz, duration);
    if (dt > duration * (1 + 1e-12)) refuse(scene, "--dt-out", fmt::format("{:g} s is longer than {}", dt, run));
    // Rows refined to ≤ 1° of motion (step < dt) grow with the motion, not with --dt-out: raising
    // it does not help there (the advice once said "shorten --dt-out", which adds rows).
    const bool refined = step < dt * (1 - 1e-12);
    if (duration / step > cli_limits::kMaxOutputRows)
      refuse(scene, whose,
             refined ? fmt::format("{} needs {:.3g} rows at most 1° of motion apart, more than {:g}: {}", run,
                                   duration / step, cli_limits::kMaxOutputRows,
                                   a.duration ? "shorten --duration" : "lower the cadence")
                     : fmt::format("{} at --dt-out {:g} s makes {:.3g} rows, more than {:g}: {} or raise --dt-out",
                                   run, dt, duration / step, cli_limits::kMaxOutputRows,
                                   a.duration ? "shorten --duration" : "raise the cadence"));
    m = constant_rate_motion(scene.initial.q, 2 * M_PI * *a.cadence_hz, duration, step);
    m.how = fmt::format("constant rate {:g} rev/s from q = {:g}°", *a.cadence_hz, scene.initial.q * 180 / M_PI);
  } else {
    m = profile_motion(a.profile, revolute, a.duration, step, cli_limits::kMaxOutputRows);
    // The profile's own span is what is short (a profile whose times are 1e-300 s apart).
    if (dt > m.t.back() * (1 + 1e-12))
      throw models::SceneError(a.profile, 0, "t",
                               fmt::format("the profile lasts {:g} s, shorter than --dt-out {:g} s: give times in "
                                           "seconds over the motion, or a shorter --dt-out",
                                           m.t.back(), dt));
    m.how = "profile " + a.profile + " (natural cubic spline, from its first time)";
  }
  return m;
}

// The motion on a grid fine enough for its statistics, and `k`: the output keeps every k-th row.
struct DriveMotion {
  PrescribedMotion motion;
  long k = 1;
};

// The motion is computed on a grid fine enough for its statistics — at most 1° of q between
// rows (0.001 m for a slider), and the output grid itself — and the output keeps every k-th row
// (run.json's peaks and means from 0.5 s rows missed the parallelogram's peak by 13 %).
DriveMotion calc_drive_motion(const DriveArgs& a, const models::Scene& scene, bool revolute, double dt) {
  const PrescribedMotion coarse = calc_motion_at(a, scene, revolute, dt, dt);
  double rate_max = 0.0;
  for (double v : coarse.qdot) rate_max = std::max(rate_max, std::abs(v));
  const double row_step = revolute ? M_PI / 180 : 1e-3;  // [rad or m] between statistics rows
  const long k = std::max(1L, static_cast<long>(std::ceil(dt * rate_max / row_step - 1e-9)));
  if (static_cast<double>(k) * static_cast<double>(coarse.t.size()) > cli_limits::kMaxOutputRows)
    refuse(scene, a.cadence_hz ? "--duration" : "--profile",
           fmt::format("the motion needs {:.3g} rows of at most 1° each; at most {:g}",
                       static_cast<double>(k) * static_cast<double>(coarse.t.size()), cli_limits::kMaxOutputRows));
  DriveMotion d{k == 1 ? coarse : calc_motion_at(a, scene, revolute, dt, dt / static_cast<double>(k)), k};
  // One projection per row and per 5° of motion: without --duration the run is one revolution,
  // so its length is the cadence's; name the option the user gave (was "--duration" when none was).
  if (a.model == "full" && calc_drive_moves(d.motion) > kMaxDriveMoves)
    refuse(scene, !a.cadence_hz ? "--profile" : a.duration ? "--duration" : "--cadence-hz",
           fmt::format("the full model would make {:.3g} projections, one per computed row ({} over {:g} s: the --dt-out "
                       "{:g} s grid refined to ≤ 1° of motion) and one per 5° (at most {:g}, about a minute): {} or use "
                       "--model reduced",
                       calc_drive_moves(d.motion), d.motion.t.size(), d.motion.t.back(), dt, kMaxDriveMoves,
                       !a.cadence_hz ? "raise --dt-out, shorten the profile"
                       : a.duration  ? "raise --dt-out, shorten --duration"
                                     : "raise --dt-out or the cadence"));
  return d;
}

// The drive the chosen model needs along the motion; the reduced model's settings go into `run`.
DriveRecord calc_drive_record(const DriveArgs& a, const models::Scene& scene, const PrescribedMotion& motion,
                              const reduced::Samples* table, nlohmann::json& run) {
  if (a.model == "full") return calc_drive_full(scene, motion);
  // Joint outputs as `simulate --model reduced` gives them: `reactions: all` those it can (the
  // others named), listed ones or refused.
  const models::Scene oscene = reduced_output_scene(scene, run);
  const models::Scene rscene = reduced::wants_joint_outputs(oscene) ? reduced::with_reaction_requests(oscene) : oscene;
  if (table) {  // a table in memory (the Python module's Table)
    const auto model = reduced::make_reduced_model(*table, rscene, reduced::parse_interpolation(a.interpolation));
    warn_coarse_table(*table, run);
    run.update({{"table", table->file.empty() ? std::string("(in memory)") : table->file},
                {"interpolation", model.table.fit}});
    return calc_drive_reduced(oscene, model, motion);
  }
  double grid = a.grid_deg;  // a default grid refined where it does not resolve the mechanism
  auto e = extract_resolving(rscene, a.grid_deg, a.grid_given, reduced::Method::Kinetostatic, grid);
  // The drive on a table, as a run the grid check compares: the drive is a joint output there
  // (its column's name), q̇ the motion's own.
  struct GridRun {
    DriveRecord r;
    models::TimeSeries ts;
    std::string fit;
    double extraction_ms = 0.0;
  };
  const std::string drive_name = scene.find_joint(scene.independent)->type == models::JointType::Revolute
                                     ? "drive_Nm" : "drive_N";
  auto run_on = [&](const reduced::Samples& samples, double extraction_ms) {
    const auto model = reduced::make_reduced_model(samples, rscene, reduced::parse_interpolation(a.interpolation));
    GridRun g{calc_drive_reduced(oscene, model, motion), {}, model.table.fit, extraction_ms};
    g.ts.t = g.r.t;
    g.ts.q = g.r.q;
    g.ts.qdot = g.r.qdot;
    g.ts.force_names = g.r.force_names;
    g.ts.forces = g.r.forces;
    g.ts.column_names = g.r.column_names;
    g.ts.columns = g.r.columns;
    g.ts.column_names.insert(g.ts.column_names.begin(), drive_name);
    g.ts.columns.insert(g.ts.columns.begin(), g.r.drive);
    return g;
  };
  warn_coarse_table(e.samples, run);
  GridRun kept = run_on(e.samples, e.extraction_ms);
  if (!a.grid_given) {  // a default grid is checked on half of it, as simulate checks it
    GridCheck check;
    kept = check_grid_by_runs(
        std::move(kept), grid,
        [&](double g) {
          auto x = extract_from_full(rscene, g, reduced::Method::Kinetostatic);
          return run_on(x.samples, x.extraction_ms);
        },
        true, check);
    grid = check.grid_deg;
    run["grid_check"] = grid_check_json(check);
    if (!check.verified) {
      const std::string why = check.not_compared.empty()
                                  ? fmt::format("{} changes {:.2g} % of its peak", check.column, 100 * check.change)
                                  : check.not_compared;
      std::fprintf(stderr,
                   "rdyn: warning: the reduced drive on the %g° table was not confirmed on half its grid (%s); compare "
                   "it with --model full (run.json: grid_check)\n",
                   grid, why.c_str());
    }
  }
  run.update({{"grid_deg", grid}, {"interpolation", kept.fit}, {"extraction_ms", kept.extraction_ms}});
  if (grid != a.grid_deg) run["grid_refined_from_deg"] = a.grid_deg;
  return std::move(kept.r);
}

// run.json's results: the drive's statistics, the constraint-force peaks and the motor check.
void add_drive_results(nlohmann::json& run, const PrescribedMotion& motion, const DriveRecord& r,
                       const DriveStats& st, double dt, bool revolute, const std::optional<MotorCheck>& mc) {
  run.update({{"motion", motion.how},
              {"duration_s", r.t.back()},
              {"output_interval_s", dt},
              {"drive_unit", revolute ? "N·m" : "N"},
              {"drive_rms", st.rms},
              {"drive_peak", st.peak},
              {"drive_mean", st.mean},
              {"mean_power_W", st.mean_power_W},
              {"peak_power_W", st.peak_power_W},
              {"wall_s", r.wall_s}});
  nlohmann::json peaks = nlohmann::json::object();
  for (size_t c = 0; c < r.force_names.size(); ++c) peaks[r.force_names[c]] = st.force_peaks[c];
  run["constraint_force_peaks_N"] = peaks;
  // Each joint output's largest |value| along the motion (a reaction's peak for bearing sizing;
  // units as the column's: N, N·m, rad …).
  nlohmann::json joint_peaks = nlohmann::json::object();
  for (size_t c = 0; c < r.column_names.size(); ++c) {
    double pk = 0.0;
    for (double v : r.columns[c]) pk = std::max(pk, std::abs(v));
    joint_peaks[r.column_names[c]] = pk;
  }
  if (!r.column_names.empty()) run["joint_output_peaks"] = joint_peaks;
  run["statistics_rows"] = r.t.size();
  if (mc)
    run["motor_check"] = {{"stall", mc->stall},
                          {"no_load_speed", mc->no_load_speed},
                          {"covers", mc->covers},
                          {"min_margin", mc->min_margin},
                          {"min_margin_fraction_of_stall", mc->min_margin_fraction},
                          {"at_t_s", mc->at_t},
                          {"at_q", revolute ? mc->at_q * 180 / M_PI : mc->at_q},
                          {"at_q_unit", revolute ? "deg" : "m"},
                          {"drive_there", mc->drive_there},
                          {"line_there", mc->line_there}};
}

}  // namespace

namespace {

// Everything checked and planned before any work or output: the option values, the motor and
// the motion (a profile is read here).
struct DrivePlan {
  bool revolute = true;
  double dt = 0.0;  // output interval [s]
  std::optional<std::pair<double, double>> motor;
  DriveMotion d;
};

DrivePlan plan_drive(const models::Scene& scene, const DriveArgs& a) {
  DrivePlan p;
  p.revolute = scene.find_joint(scene.independent)->type == models::JointType::Revolute;
  p.dt = a.dt_out.value_or(scene.simulation.output_interval_s);
  check_drive_arguments(a, scene, p.revolute, p.dt);
  p.motor = parse_motor_option(a, scene, p.revolute);
  p.d = calc_drive_motion(a, scene, p.revolute, p.dt);
  return p;
}

DriveRun run_drive_plan(const models::Scene& scene, const DriveArgs& a, const DrivePlan& p,
                        const reduced::Samples* table) {
  nlohmann::json run = {{"scene", scene.name}, {"scene_file", scene.source_file}, {"model", a.model}};
  if (a.cadence_hz) run["cadence_hz"] = *a.cadence_hz;
  else run["profile"] = a.profile;
  const DriveRecord r = calc_drive_record(a, scene, p.d.motion, table, run);
  const DriveStats st = calc_drive_stats(r);
  std::optional<MotorCheck> mc;
  if (p.motor) mc = calc_motor_check(r, p.motor->first, p.motor->second);
  add_drive_results(run, p.d.motion, r, st, p.dt, p.revolute, mc);
  return {every_kth_row(r, p.d.k), std::move(run), p.revolute};
}

}  // namespace

DriveRun drive_scene(const models::Scene& scene, const DriveArgs& a, const reduced::Samples* table) {
  return run_drive_plan(scene, a, plan_drive(scene, a), table);
}

int run_drive(const DriveArgs& a) {
  std::vector<models::Override> overrides;
  for (const auto& s : a.sets) overrides.push_back(models::parse_override(s));
  const models::Scene scene = models::load_scene(a.scene, overrides);
  const DrivePlan plan = plan_drive(scene, a);  // every argument before the output folder is touched
  OutputDir out(a.out, a.force);                // fails early on an unusable folder
  const DriveRun d = run_drive_plan(scene, a, plan, nullptr);
  write_drive_csv(out.file("timeseries.csv"), d.rows, d.revolute);
  write_text_file(out.file("run.json"), d.run.dump(2) + "\n");
  out.commit();
  const char* unit = d.revolute ? "N·m" : "N";
  const auto& run = d.run;
  std::fprintf(stderr, "rdyn: %s (%s model) driven by %s: drive RMS %.4g %s, peak %.4g %s, mean power %.4g W; wrote %s\n",
               scene.name.c_str(), a.model.c_str(), run["motion"].get<std::string>().c_str(),
               run["drive_rms"].get<double>(), unit, run["drive_peak"].get<double>(), unit,
               run["mean_power_W"].get<double>(), (a.out + "/timeseries.csv").c_str());
  if (run.contains("motor_check")) {
    const auto& mc = run["motor_check"];
    const double at_q = mc["at_q"].get<double>() * (d.revolute ? M_PI / 180 : 1.0);
    std::fprintf(stderr, "rdyn: motor %s: %s (smallest margin %.4g %s, %.3g %% of stall, at t = %.6g s, %s)\n",
                 a.motor.c_str(), mc["covers"].get<bool>() ? "covers the drive at every row" : "does NOT cover the drive",
                 mc["min_margin"].get<double>(), unit, 100 * mc["min_margin_fraction_of_stall"].get<double>(),
                 mc["at_t_s"].get<double>(), reduced::describe_q(d.revolute, at_q, 6).c_str());
  }
  return 0;
}

}  // namespace rdyn::validate
