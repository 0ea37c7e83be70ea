#include "validate/cli/optimize_command.hpp"

#include <cmath>
#include <cstdio>
#include <tuple>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "models/scene_write.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/optimize.hpp"
#include "validate/report/optimize_report.hpp"
#include "validate/report/cycle_animation.hpp"
#include "validate/analysis/cycle_run.hpp"
#include "validate/cli/animate_command.hpp"
#include "engine/full_model.hpp"
#include "engine/inspect.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {

OptimizeOptions optimize_options_of(const models::Scene& scene, const OptimizeArgs& a) {
  auto bad = [&](const std::string& option, const std::string& msg) {
    throw models::SceneError(scene.source_file, 0, option, msg);
  };
  // Every number before any work (ranges as calibrate's).
  if (a.cadence_given && !(a.cadence_hz > 0 && a.cadence_hz <= models::limits::kMaxCadence_Hz))
    bad("--cadence-hz", fmt::format("must be in (0, {:g}] Hz", models::limits::kMaxCadence_Hz));
  if (a.power_given && !(a.power_w > 0 && a.power_w <= models::limits::kMaxPower_W))
    bad("--power-w", fmt::format("must be in (0, {:g}] W", models::limits::kMaxPower_W));
  if (!(a.grid_deg >= 0.05 && a.grid_deg <= 90)) bad("--grid-deg", "must be in [0.05, 90] deg");
  if (a.harmonics && !(*a.harmonics >= 1 && *a.harmonics <= models::kMaxOptimizeHarmonics))
    bad("--harmonics", fmt::format("must be a whole number in [1, {}] (got {})", models::kMaxOptimizeHarmonics,
                                   *a.harmonics));
  if (a.force_name_given && a.force_name.empty()) bad("--force-name", "an empty name names no constraint force");
  if (a.p && !(*a.p >= 2 && *a.p <= 64)) bad("--p", fmt::format("must be in [2, 64] (got {:g})", *a.p));
  if (a.max_load && !(*a.max_load > 0 && *a.max_load <= models::limits::kMaxForce))
    bad("--max-load", fmt::format("must be in (0, {:g}] N·m or N (got {:g})", models::limits::kMaxForce, *a.max_load));
  const std::string objective =
      !a.objective.empty() ? a.objective : scene.optimize ? scene.optimize->objective : std::string("peak");
  if (a.p && objective != "pnorm") bad("--p", "an exponent needs --objective pnorm");
  const auto copt = calibration_options_of(scene, a.cadence_given ? a.cadence_hz : 0.0, a.power_given ? a.power_w : 0.0,
                                           "");
  OptimizeOptions opt;
  opt.cadence_hz = copt.cadence_hz > 0 ? copt.cadence_hz : a.cadence_hz;
  opt.power_w = copt.power_w;
  opt.harmonics = a.harmonics.value_or(0);
  opt.objective = a.objective;
  opt.p = a.p.value_or(0.0);
  opt.max_load = a.max_load.value_or(0.0);
  opt.force_name = a.force_name;
  opt.add_torques = a.add_torques;
  opt.add_torque_max = a.add_torque_max;
  opt.max_evaluations = a.max_evaluations;
  opt.rel_tolerance = a.rel_tolerance;
  // The operating point's table: --grid-deg, else the scene's validation.calibrate.grid_deg (as
  // calibrate; a scene whose 10° table is too coarse there declares a finer one), else 10°.
  opt.grid_deg = a.grid_given || !(copt.grid_deg > 0) ? a.grid_deg : copt.grid_deg;
  opt.grid_given = a.grid_given || copt.grid_given;  // else 10°, halved while it does not resolve m1
  opt.interpolation = a.interpolation;
  opt.full_duration_s = a.full_duration_s;
  opt.full_skip_s = std::min(2.0, 0.5 * a.full_duration_s);
  check_optimize_options(scene_with_added_torques(scene, opt), opt);
  return opt;
}

int run_optimize(const OptimizeArgs& a) {
  std::vector<models::Override> overrides;
  for (const auto& s : a.sets) overrides.push_back(models::parse_override(s));
  const models::Scene scene = models::load_scene(a.scene, overrides);
  const OptimizeOptions opt = optimize_options_of(scene, a);
  OutputDir dir(a.out, a.force);  // fails early on an unusable destination
  Progress progress;
  const auto r = optimize(scene, opt, progress);
  const std::string failure = optimize_failure_message(r);
  if (!failure.empty()) throw models::NumericalError(failure);
  auto summary = optimize_summary(r);
  summary["nonnegative_repair"] = r.nonnegative_repair;
  summary["grid_deg"] = r.grid_deg;  // the table's grid (--grid-deg, the scene's validation.calibrate, or refined)
  if (r.grid_deg != opt.grid_deg) summary["grid_refined_from_deg"] = opt.grid_deg;
  // The mechanism drawn, and both strategies over one steady cycle of the full model from their
  // steady points (analysis/cycle_run.hpp), which the report shows side by side.
  summary["mechanism_svg"] =
      inspect_svg(r.optimised_scene, engine::calc_inspection(engine::FullModel(r.optimised_scene)));
  for (const auto& [key, sc, sr] : {std::tuple{"constant", &r.constant_scene, &r.constant},
                                    std::tuple{"optimised", &r.optimised_scene, &r.optimised}}) {
    const CycleStart c{0.0, sr->steady_q, sr->steady_qdot, 1.0 / sr->cadence_full_hz};
    summary["animations"][key] = animation_record(
        *sc, c, simulate_cycle(*sc, c),
        fmt::format("{} strategy: peak {} {:.1f} N (full model)", key, r.force_name, sr->peak_full_N));
  }
  render_optimize_report(summary, dir.file(""));
  // The optimised scene, loadable by every command (read back and checked by the writer).
  write_text_file(dir.file("optimised.yaml"),
                  "# Written by `rdyn optimize` from " + scene.name + ": the design loads profiled at the optimum, the "
                  "calibrated amplitude and resistance, steady initial conditions.\n" +
                      models::scene_to_yaml_checked(r.optimised_scene));
  dir.commit();
  // The headline numbers on standard output (the whole record is DIR/summary.json).
  nlohmann::json head = {{"scene", r.scene},
                         {"force_name", r.force_name},
                         {"peak_force_full_N", {{"constant", r.constant.peak_full_N}, {"optimised", r.optimised.peak_full_N}}},
                         {"peak_force_reduced_N",
                          {{"constant", r.constant.peak_reduced_N}, {"optimised", r.optimised.peak_reduced_N}}},
                         {"peak_reduction_full", r.reduction_full},
                         {"mean_cadence_hz_full", {{"constant", r.constant.cadence_full_hz}, {"optimised", r.optimised.cadence_full_hz}}},
                         {"evaluations", r.evaluations},
                         {"nonnegative_repair", r.nonnegative_repair},
                         {"wall_time_s", r.wall_time_s},
                         {"out", a.out}};
  std::printf("%s\n", head.dump(2).c_str());
  return 0;
}

}  // namespace rdyn::validate
