#include "validate/summary.hpp"

#include <gtest/gtest.h>

#include "tests/validate/validation_fixture.hpp"

namespace rdyn::validate {
namespace {

// Every number in the tree is finite (JSON has no NaN; unmeasured values are null).
void expect_finite(const nlohmann::json& j, const std::string& path = "") {
  if (j.is_number_float()) EXPECT_TRUE(std::isfinite(j.get<double>())) << path;
  if (j.is_structured())
    for (auto it = j.begin(); it != j.end(); ++it) expect_finite(*it, path + "/" + (j.is_object() ? it.key() : "[]"));
}

TEST(Summary, HoldsTheVerdictsBaselinesAndFigureData) {
  const auto v = test::synthetic_validation();
  const auto s = summary_json(v);
  expect_finite(s);
  EXPECT_EQ(s["recommended_reduced"]["label"], v.runs[2].label());
  ASSERT_EQ(s["verdicts"].size(), 3u);
  EXPECT_EQ(s["verdicts"][1]["quantity"], "F");
  EXPECT_EQ(s["verdicts"][1]["pass"], true);
  EXPECT_DOUBLE_EQ(s["baselines"][0]["speedup"].get<double>(), 1000.0);  // reference 3 s / 3 ms
  EXPECT_TRUE(s["runs"][4]["wall_s"].is_null());                        // the stopped run
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
  c.drive_work_per_rev_per_Nm = 2.0;
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

}  // namespace
}  // namespace rdyn::validate
