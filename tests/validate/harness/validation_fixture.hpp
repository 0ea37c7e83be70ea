// A small synthetic validation result (no simulation): two full runs, three reduced runs, a
// threshold, a calibration, a scene name and note full of markup; for the summary and report
// tests.
#pragma once

#include <cmath>

#include "tests/validate/harness/run_records.hpp"
#include "validate/harness/harness.hpp"
#include "validate/harness/pareto.hpp"

namespace rdyn::test {

inline models::TimeSeries sine_series(double amplitude, int n = 200) {
  models::TimeSeries ts;
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    ts.t.push_back(t);
    ts.q.push_back(2 * M_PI * t);
    ts.qdot.push_back(2 * M_PI + amplitude * std::sin(2 * M_PI * t));
  }
  ts.forces = {std::vector<double>(n, 10.0)};
  ts.force_names = {"F"};
  return ts;
}

inline validate::ValidationResult synthetic_validation() {
  validate::ValidationResult v;
  v.scene = "<script>alert(1)</script> & co";
  v.scene_file = "scenes/x.yaml";
  v.note = "a note with <b>markup</b>";
  v.machine = "test machine";
  v.duration_s = 2.0;
  v.output_interval_s = 0.01;
  v.time_scale = {1.0, 2.0, "one revolution"};
  v.fixed_steps = {1e-3, 5e-3};
  v.reference_tolerance = 1e-10;
  v.reference_run = record("full", 3.0, {});
  v.reference_change.signals = {{"qdot", 7.0, 1e-9, 1e-10}, {"F", 10.0, 2e-9, 1e-10}};
  v.reference_change.samples = 200;
  v.window = {0.0, 1, true, "compared over the whole run"};
  v.runs = {
      record("full", 1.0, {{"qdot", 1e-6}, {"F", 1e-6}, {"mean_qdot", 1e-7}}),
      record("full", 0.3, {{"qdot", 5e-4}, {"F", 6e-4}, {"mean_qdot", 1e-5}}),
      record("reduced", 0.003, {{"qdot", 2e-4}, {"F", 4e-4}, {"mean_qdot", 1e-6}}),
      record("reduced", 0.001, {{"qdot", 2e-2}, {"F", 4e-2}, {"mean_qdot", 1e-3}}),
      record("reduced", INFINITY, {{"qdot", INFINITY}, {"F", INFINITY}, {"mean_qdot", INFINITY}})};
  v.runs[3].grid_deg = 30;
  v.runs[4].failure = "diverged at t = 0.5 s";
  v.extractions = {{10.0, 12.0, 37, 36}, {30.0, 4.0, 13, 12}};
  v.extraction_ms = 12.0;
  v.tightest_tolerance = 1e-8;
  v.headline_quantity = "F";
  v.quantities = {"qdot", "F", "mean_qdot"};
  validate::mark_pareto(v.runs, "F");
  const auto m = validate::calc_matched_speedup(v.runs, "F", v.matched_target);
  v.matched_full = m.full, v.matched_reduced = m.reduced, v.speedup_at_matched_error = m.speedup;
  v.recommended = validate::pick_recommended(v.runs, {"qdot", "F"}, v.matched_target);
  v.thresholds = {{{"F", 10.0, "", 1e-3}, 4e-4, true, v.runs[2].label()}};
  validate::calc_first_screen(v);
  v.convergence = validate::calc_convergence(v.runs, "F", 1e-8, 1e-8);
  v.reference = sine_series(1.0);
  v.showcase = sine_series(1.001);
  v.showcase_run = 2;
  // A 30° table of m1 = 2 + 0.5 sin q, m2 = ½ dm1/dq, and its interpolant at 1°.
  v.samples10.step = M_PI / 6;
  std::vector<double> m1, m2;
  for (int i = 0; i < 12; ++i) {
    v.samples10.q.push_back(i * M_PI / 6);
    m1.push_back(2 + 0.5 * std::sin(i * M_PI / 6));
    m2.push_back(0.25 * std::cos(i * M_PI / 6));
  }
  v.samples10.add("m1", m1);
  v.samples10.add("m2", m2);
  v.dense_names = {"q_deg", "m1", "m2"};
  v.dense_params.assign(3, {});
  for (int d = 0; d <= 360; ++d) {
    v.dense_params[0].push_back(d);
    v.dense_params[1].push_back(2 + 0.5 * std::sin(d * M_PI / 180));
    v.dense_params[2].push_back(0.25 * std::cos(d * M_PI / 180));
  }
  return v;
}

}  // namespace rdyn::test
