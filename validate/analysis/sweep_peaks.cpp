#include "validate/analysis/sweep_peaks.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "reduced/joint_outputs.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/calibration_load.hpp"
#include "validate/analysis/drive.hpp"

namespace rdyn::validate {

namespace {

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

// `scene` asking for every joint's motion and reaction and the shaking load: the joint output
// columns it could have, to tell an unrequested one from an unknown one.
models::Scene with_every_joint_output(const models::Scene& scene) {
  models::Scene s = scene;
  s.outputs.joints.clear();
  s.outputs.reactions.clear();
  for (const auto& j : s.joints) {
    s.outputs.joints.push_back(j.name);
    s.outputs.reactions.push_back(j.name);
  }
  for (const auto& l : s.loops) s.outputs.reactions.push_back(l.name);
  s.outputs.shaking = true;
  return s;
}

// The scene key that requests joint output column `name` (one of joint_output_names).
std::string requesting_key(const std::string& name) {
  if (name.rfind("shaking_", 0) == 0) return "outputs.shaking: true";
  if (name.rfind("R_", 0) == 0) return "outputs.reactions";
  return "outputs.joints";
}

}  // namespace

models::Scene reduced_joint_output_scene(const models::Scene& scene) {
  return scene.outputs.reactions_all ? reduced::split_reduced_reactions(scene).scene : scene;
}

std::vector<std::string> peak_column_candidates(const models::Scene& scene, bool drive) {
  const models::Scene o = reduced_joint_output_scene(scene);
  std::vector<std::string> forces;
  for (const auto& f : o.outputs.constraint_forces) forces.push_back(f.name);
  // A drive sweep drives a revolute coordinate (plan_sweep checks it): drive_Nm.
  auto names = drive ? drive_column_names(forces, models::joint_output_names(o), true)
                     : models::timeseries_column_names(forces, models::joint_output_names(o));
  names.erase(names.begin());  // t: its largest value is the window's end, not a peak
  return names;
}

void check_peak_columns(const models::Scene& scene, const std::vector<std::string>& peaks, bool drive) {
  const auto candidates = peak_column_candidates(scene, drive);
  auto fail = [&](const std::string& msg) {
    std::string list;
    for (const auto& c : candidates) list += (list.empty() ? "" : ", ") + c;
    throw models::SceneError(scene.source_file, 0, "--peak", msg + "; this sweep's columns: " + list);
  };
  for (size_t i = 0; i < peaks.size(); ++i) {
    const std::string& p = peaks[i];
    if (std::find(peaks.begin(), peaks.begin() + static_cast<long>(i), p) != peaks.begin() + static_cast<long>(i))
      fail(fmt::format("column '{}' is named twice; give it once", p));
    if (contains(candidates, p)) continue;
    if (p == "t") fail("t is the time; its largest value is the window's end, not a peak");
    if (contains(models::joint_output_names(scene), p))  // `reactions: all` and the reduced model cannot give it
      fail(fmt::format("the reduced model does not give column '{}' (`rdyn simulate --model reduced` names why)", p));
    if (contains(models::joint_output_names(with_every_joint_output(scene)), p))
      fail(fmt::format("column '{}' is not requested by the scene: add it with {}", p, requesting_key(p)));
    fail(fmt::format("no column '{}' in a reduced run of this scene", p));
  }
}

bool peaks_need_joint_outputs(const models::Scene& scene, const std::vector<std::string>& peaks) {
  const auto joint = models::joint_output_names(reduced_joint_output_scene(scene));
  return std::any_of(peaks.begin(), peaks.end(), [&](const std::string& p) { return contains(joint, p); });
}

models::Scene peak_table_scene(const models::Scene& scene, const std::vector<std::string>& peaks) {
  if (!peaks_need_joint_outputs(scene, peaks)) return scene;
  return reduced::with_reaction_requests(reduced_joint_output_scene(scene));
}

std::vector<std::string> sweep_table_columns(const models::Scene& scene, const std::vector<std::string>& peaks) {
  const models::Scene table_scene = peak_table_scene(scene, peaks);
  auto names = reduced::reduced_model_columns(table_scene);
  if (peaks_need_joint_outputs(scene, peaks)) {
    const auto joint = reduced::joint_output_columns(table_scene);
    names.insert(names.end(), joint.begin(), joint.end());
  }
  return names;
}

std::vector<double> calc_column_peaks(const std::vector<std::string>& names,
                                      const std::function<const std::vector<double>&(size_t)>& column,
                                      const std::vector<std::string>& peaks) {
  std::vector<double> out;
  for (const auto& p : peaks) {
    const auto it = std::find(names.begin(), names.end(), p);
    if (it == names.end()) throw std::invalid_argument("calc_column_peaks: the run has no column " + p);
    double peak = 0.0;
    for (const double v : column(static_cast<size_t>(it - names.begin()))) {
      if (!std::isfinite(v)) throw models::NumericalError("the reduced run's column " + p + " has a non-finite value");
      peak = std::max(peak, std::abs(v));
    }
    out.push_back(peak);
  }
  return out;
}

models::TimeSeries simulate_steady_cycle(const models::Scene& scene, const models::Scene& table_scene,
                                         const CalibrationTable& table, const CalibrationOptions& opt,
                                         const CalibrationResult& r, bool joint_outputs) {
  const auto model = reduced::make_reduced_model(table.samples, scene_at_operating_point(table_scene, opt, r),
                                                 table.table);
  // One period from the cycle's own point: the window the steady cycle's peaks are taken over.
  reduced::ReducedOptions ro;
  ro.duration_s = 1.0 / r.mean_cadence_hz_reduced;
  ro.output_interval_s = ro.duration_s / kPeakCycleRows;
  ro.tolerance = opt.tolerance;
  ro.step_outputs = true;  // rows to the integrator's tolerance, not the Hermite interpolant's
  auto ts = reduced::simulate_reduced(model, r.steady_q, r.steady_qdot, ro);
  if (joint_outputs) reduced::add_joint_outputs(reduced_joint_output_scene(scene), model, ts);
  return ts;
}

std::vector<double> calc_steady_cycle_peaks(const models::Scene& scene, const models::Scene& table_scene,
                                            const CalibrationTable& table, const CalibrationOptions& opt,
                                            const CalibrationResult& r, const std::vector<std::string>& peaks) {
  const auto ts = simulate_steady_cycle(scene, table_scene, table, opt, r, peaks_need_joint_outputs(scene, peaks));
  return calc_column_peaks(
      models::timeseries_column_names(ts), [&](size_t k) -> const std::vector<double>& { return models::timeseries_column(ts, k); },
      peaks);
}

}  // namespace rdyn::validate
