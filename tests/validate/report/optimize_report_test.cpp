// The outputs of rdyn optimize are rendered from the summary record alone: the CSV and the HTML
// come from summary.json's fields (a saved summary re-renders the same), scene text escaped.
#include "validate/report/optimize_report.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace rdyn::validate {
namespace {

OptimizeResult synthetic() {
  OptimizeResult r;
  r.scene = "a<b>&c";
  r.force_name = "knee";
  r.objective = "peak";
  r.harmonics = 1;
  r.independent = r.profile_of = "crank";
  r.cadence_hz = 1.0;
  r.power_w = 125.0;
  r.full_duration_s = 20.0;
  r.design_loads = {"hip_r", "hip_l"};
  r.same_as = {"", "hip_r"};
  r.shift_deg = {0.0, 180.0};
  for (auto* s : {&r.constant, &r.optimised}) {
    s->a0 = {1.0, 1.0};
    s->a = {{0.5}, {-0.5}};
    s->b = {{0.0}, {0.0}};
    s->curves.torque_Nm.assign(2, std::vector<double>(360));
    for (int i = 0; i < 360; ++i) {
      s->curves.angle_deg.push_back(i);
      s->curves.torque_Nm[0][i] = 10 + std::cos(i * M_PI / 180);
      s->curves.torque_Nm[1][i] = 20.0;
      s->curves.force_reduced_N.push_back(100 + i);
    }
  }
  r.constant.peak_full_N = 700, r.optimised.peak_full_N = 230;
  r.constant.curves.force_full_N.assign(360, 5.0);  // the optimum's full curve is missing (empty)
  r.constant.cadence_full_hz = r.optimised.cadence_full_hz = 1.0;
  r.full_cadence_ok = r.full_better = true;
  r.reduction_full = 1 - 230.0 / 700.0;
  return r;
}

TEST(OptimizeReport, CsvAndHtmlFromTheSummaryAlone) {
  const auto s = optimize_summary(synthetic());
  EXPECT_EQ(s["status"], "pass");
  const std::string csv = optimize_profile_csv(s);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 361);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "q_deg,hip_r_constant,hip_r_optimised,hip_l_constant,hip_l_optimised,F_knee_constant_reduced,"
            "F_knee_optimised_reduced,F_knee_constant_full,F_knee_optimised_full");
  // Row 90°: cos 90° ≈ 0 → 10; the reduced force 190; the missing full curve is an empty field.
  const auto row = csv.substr(csv.find("\n90,") + 1, csv.find('\n', csv.find("\n90,") + 1) - csv.find("\n90,") - 1);
  EXPECT_EQ(row, "90,10,10,20,20,190,190,5,");
  // A saved summary (JSON text) renders the same report.
  const auto again = nlohmann::json::parse(s.dump());
  EXPECT_EQ(render_optimize_html(again, {}), render_optimize_html(s, {}));
  EXPECT_EQ(optimize_profile_csv(again), csv);
  const std::string html = render_optimize_html(s, {{"torques", "<?xml?><svg>t</svg>"}});
  EXPECT_NE(html.find("a&lt;b&gt;&amp;c"), std::string::npos);
  EXPECT_EQ(html.find("a<b>"), std::string::npos);
  EXPECT_NE(html.find("<svg>t</svg>"), std::string::npos);
  EXPECT_NE(html.find("force.svg could not be rendered"), std::string::npos);
  EXPECT_NE(html.find("67.1 % lower"), std::string::npos) << html.substr(0, 2000);
}

TEST(OptimizeReport, AMissedTargetIsAFailedStatus) {
  auto r = synthetic();
  r.full_better = false;
  EXPECT_EQ(optimize_summary(r)["status"], "fail");
  EXPECT_NE(optimize_failure_message(r).find("not better"), std::string::npos);
  r.full_cadence_ok = false;
  EXPECT_NE(optimize_failure_message(r).find("misses the cadence"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
