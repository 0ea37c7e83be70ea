#include "validate/harness/summary.hpp"

#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"
#include "tests/validate/harness/validation_fixture.hpp"

namespace rdyn::validate {
namespace {

// Every number in the tree is finite (JSON has no NaN; unmeasured values are null).
void expect_finite(const nlohmann::json& j, const std::string& path = "") {
  if (j.is_number_float()) {
    EXPECT_TRUE(std::isfinite(j.get<double>())) << path;
  }
  if (j.is_structured())
    for (auto it = j.begin(); it != j.end(); ++it)
      expect_finite(*it, path + "/" + (j.is_object() ? it.key() : "[]"));
}

TEST(Summary, BreaksTheExtractionTimeIntoStages) {
  auto v = test::synthetic_validation();
  v.extraction_stages = {0.5, 1.25, 10.25};
  const auto s = summary_json(v);
  EXPECT_DOUBLE_EQ(s["extraction_ms"].get<double>(), 12.0);
  EXPECT_DOUBLE_EQ(s["extraction_stages_ms"]["system_build"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(s["extraction_stages_ms"]["assembly"].get<double>(), 1.25);
  EXPECT_DOUBLE_EQ(s["extraction_stages_ms"]["kinetostatics"].get<double>(), 10.25);
}

TEST(Summary, HoldsTheVerdictsBaselinesAndFigureData) {
  const auto v = test::synthetic_validation();
  const auto s = summary_json(v);
  expect_finite(s);
  EXPECT_EQ(s["recommended_reduced"]["label"], v.runs[2].label());
  ASSERT_EQ(s["verdicts"].size(), 3u);
  EXPECT_EQ(s["verdicts"][1]["quantity"], "F");
  EXPECT_EQ(s["verdicts"][1]["within_target"], true);
  EXPECT_EQ(s["recommended_full"]["label"], v.runs[0].label());
  EXPECT_DOUBLE_EQ(s["recommended_speedup"].get<double>(), 1.0 / 0.003);
  EXPECT_DOUBLE_EQ(s["baselines"][0]["speedup"].get<double>(), 1000.0);  // reference 3 s / 3 ms
  EXPECT_TRUE(s["runs"][4]["wall_s"].is_null());                         // the stopped run
  EXPECT_EQ(s["runs"][4]["failure"], "diverged at t = 0.5 s");
  EXPECT_EQ(s["steady_window"]["whole_run"], true);
  EXPECT_EQ(s["per_second_measured"], true);  // 2 s simulated
  // The figure data: the reference and the showcase over the last three periods (3 × 1 s,
  // capped at the run's start).
  const auto& ts = s["figures"]["timeseries"];
  EXPECT_EQ(ts["names"][1], "qdot_full");
  EXPECT_EQ(ts["rows"].size(), v.reference.t.size());
  EXPECT_DOUBLE_EQ(ts["rows"][50][2].get<double>(), v.showcase.qdot[50]);
  EXPECT_FALSE(s.contains("calibration"));
}

TEST(Summary, CalibrationUnderNeutralNamesWithTheScenesComparison) {
  auto v = test::synthetic_validation();
  CalibrationResult c;
  c.torque_Nm = 60.0;
  c.work_per_rev_per_unit = 2.0;
  c.mean_cadence_hz_full = NAN;  // full-model check skipped
  v.calibration = c;
  v.calibration_options.cadence_hz = 1.0;
  v.calibration_options.power_w = 125.0;
  v.compare = {{"drive_torque_Nm", 69.7, "N·m", "a paper", "because"}};
  const auto s = summary_json(v);
  const auto& cal = s["calibration"];
  EXPECT_DOUBLE_EQ(cal["drive_torque_Nm"].get<double>(), 60.0);
  EXPECT_TRUE(cal["mean_cadence_hz_full"].is_null());
  ASSERT_EQ(cal["compare"].size(), 1u);
  EXPECT_DOUBLE_EQ(cal["compare"][0]["value"].get<double>(), 69.7);
  EXPECT_DOUBLE_EQ(cal["compare"][0]["rdyn_value"].get<double>(), 60.0);
  EXPECT_FALSE(cal.contains("hip_torque_Nm"));
}

// The drive cycle's record: each model's statistics, reduced − full differences, the curve in
// degrees (a record the report re-draws from alone).
TEST(Summary, DriveCycleRecordHoldsBothModelsAndTheirDifference) {
  auto v = test::synthetic_validation();
  DriveCycleComparison c;
  c.cadence_hz = 1.0;
  c.q0 = M_PI / 2;
  for (int i = 0; i <= 4; ++i) {
    c.full.t.push_back(0.25 * i), c.full.q.push_back(M_PI / 2 + i * M_PI / 2);
    c.full.drive.push_back(10.0 + i);
  }
  c.reduced = c.full;
  c.reduced.drive = {10.5, 11, 12, 13, 14};
  c.full_stats.rms = 12.0, c.full_stats.peak = 14.0, c.full_stats.mean_power_W = 75.0;
  c.reduced_stats.rms = 12.1, c.reduced_stats.peak = 14.0, c.reduced_stats.mean_power_W = 76.0;
  c.max_difference = 0.5;
  c.rms_difference = 0.2;
  v.drive_cycle = c;
  const auto s = summary_json(v);
  expect_finite(s);
  const auto& d = s["drive_cycle"];
  EXPECT_DOUBLE_EQ(d["q0_deg"].get<double>(), 90.0);
  EXPECT_DOUBLE_EQ(d["full"]["rms_Nm"].get<double>(), 12.0);
  EXPECT_DOUBLE_EQ(d["reduced"]["rms_Nm"].get<double>(), 12.1);
  EXPECT_NEAR(d["rms_difference_Nm"].get<double>(), 0.1, 1e-12);
  EXPECT_DOUBLE_EQ(d["peak_difference_Nm"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(d["mean_power_difference_W"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(d["max_abs_difference_rel_peak"].get<double>(), 0.5 / 14.0);
  ASSERT_EQ(d["curve"]["rows"].size(), 5u);
  EXPECT_EQ(d["curve"]["names"][3], "drive_reduced_Nm");
  EXPECT_DOUBLE_EQ(d["curve"]["rows"][4][0].get<double>(), 450.0);  // q [deg]
  EXPECT_DOUBLE_EQ(d["curve"]["rows"][0][3].get<double>(), 10.5);
  EXPECT_FALSE(summary_json(test::synthetic_validation()).contains("drive_cycle"));
}

// The comparison lives in the scene (validation.compare), read with file, line and field.
TEST(Summary, SceneDeclaresItsComparison) {
  const auto bicycle = models::load_scene("bicycle");
  ASSERT_EQ(bicycle.validation.compare.size(), 1u);
  EXPECT_EQ(bicycle.validation.compare[0].quantity, "drive_torque_Nm");
  EXPECT_DOUBLE_EQ(bicycle.validation.compare[0].value, 69.7);
  EXPECT_FALSE(bicycle.validation.compare[0].explanation.empty());
  EXPECT_TRUE(models::load_scene("fourbar").validation.compare.empty());
  const std::string base = "name: x\nbicycle_leg: {}\nvalidation:\n";
  try {
    models::parse_scene(base +
                            "  calibrate: {cadence_Hz: 1, power_W: 100}\n  compare: [{quantity: "
                            "torque, value: 1}]\n",
                        "x.yaml");
    FAIL() << "an unknown quantity was accepted";
  } catch (const models::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("validation.compare[0].quantity"), std::string::npos)
        << e.what();
  }
  // Compared values are calibration results: without calibrate there is nothing to compare.
  EXPECT_THROW(
      models::parse_scene(base + "  compare: [{quantity: drive_torque_Nm, value: 1}]\n", "x.yaml"),
      models::SceneError);
  EXPECT_THROW(models::parse_scene(
                   base + "  calibrate: {cadence_Hz: 1, power_W: 100}\n  compare: [{quantity: "
                          "drive_torque_Nm, value: .nan}]\n",
                   "x.yaml"),
               models::SceneError);
}

}  // namespace
}  // namespace rdyn::validate
