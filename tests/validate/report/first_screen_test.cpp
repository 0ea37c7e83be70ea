// The first screen of a validation report (issue #23): one recommended setting, one speedup (that
// setting against the cheapest full run at equal or better error) and every error on it read on
// that setting; the other runs (the 10° run drawn in figure 2, the matched-target pair of figure
// 3) only below it. Drawn from summary.json alone.
#include "validate/report/first_screen.hpp"

#include <gtest/gtest.h>

#include "tests/validate/harness/validation_fixture.hpp"
#include "validate/harness/summary.hpp"
#include "validate/report/report.hpp"

namespace rdyn::validate {
namespace {

// The fixture with labels that tell every run apart: full runs at 1e-10 (1 s) and 1e-4 (0.3 s),
// reduced 5° (the recommended, 3 ms), 30° (1 ms, 2 % off) and a stopped run; figure 2 draws the
// 30° run.
ValidationResult distinct_runs() {
  auto v = test::synthetic_validation();
  v.runs[0].tolerance = 1e-10;
  v.runs[1].tolerance = 1e-4;
  v.runs[2].grid_deg = 5;
  v.showcase_run = 3;
  analyse_runs(v);
  calc_first_screen(v);
  return v;
}

std::string first_screen_of(const std::string& html) {
  const size_t from = html.find("<h2>Verdict</h2>"), to = html.find("<h2>1.");
  EXPECT_NE(from, std::string::npos);
  EXPECT_NE(to, std::string::npos);
  return html.substr(from, to - from);
}

TEST(FirstScreen, OneSettingOneSpeedupEveryErrorOnIt) {
  const auto v = distinct_runs();
  ASSERT_EQ(v.recommended, 2);
  // The 1e-4 full run (5e-4, 6e-4) is less accurate than the recommended run (2e-4, 4e-4): the
  // comparison is with the 1e-10 run, 1 s / 3 ms.
  ASSERT_EQ(v.recommended_full, 0);
  const auto s = summary_json(v);
  const std::string html = render_html(s, {});
  const std::string first = first_screen_of(html);
  EXPECT_NE(first.find(v.runs[2].label()), std::string::npos) << first;
  EXPECT_NE(first.find(v.runs[0].label()), std::string::npos) << first;
  EXPECT_NE(first.find("333× faster"), std::string::npos) << first;
  // Not the matched-target pair (the 1e-4 full run against the recommended run, quoted across
  // scenes) nor the 30° run drawn in figure 2: those are described below, where they are used.
  EXPECT_EQ(first.find("matched-error target"), std::string::npos) << first;
  EXPECT_EQ(first.find(v.runs[3].label()), std::string::npos) << first;
  EXPECT_NE(html.find("At the matched-error target", html.find("<h2>3.")), std::string::npos);
  EXPECT_NE(html.find(v.runs[3].label(), html.find("<h2>2.")), std::string::npos);
  // The error column is the recommended run's: F at 4e-4 (0.04 %), not the threshold run's.
  EXPECT_NE(first.find("<td class=l>F</td><td>0.04 %</td><td>0.1 %</td>"), std::string::npos) << first;
  // The headline names the same setting and the same speedup.
  const std::string h = headline(s);
  EXPECT_NE(h.find(v.runs[2].label()), std::string::npos) << h;
  EXPECT_NE(h.find(v.runs[0].label()), std::string::npos) << h;
  EXPECT_NE(h.find("333× faster"), std::string::npos) << h;
  EXPECT_EQ(h.find("100×"), std::string::npos) << h;
  EXPECT_EQ(h.find(v.runs[3].label()), std::string::npos) << h;
}

// Figure 2's note says what the default grid's check found: verified on half the grid, not
// converged (with the change that is left), or not compared (with why); nothing for a summary
// without the check.
TEST(FirstScreen, TheDrawnRunSaysHowItsGridWasChecked) {
  auto v = distinct_runs();
  v.default_grid_deg = 30;
  v.default_grid_check = {30, 15, 60, "F", 2e-4, true, ""};
  EXPECT_NE(showcase_note(summary_json(v)).find("changes F by 0.02 % of its peak on the 15° table"), std::string::npos)
      << showcase_note(summary_json(v));
  v.default_grid_check = {30, 0, 60, "F", 3e-2, false, ""};
  EXPECT_NE(showcase_note(summary_json(v)).find("has not converged: F still changed by 3 % of its peak between the "
                                                "60° and 30° tables (more than 0.05 %)"),
            std::string::npos)
      << showcase_note(summary_json(v));
  v.default_grid_check = {30, 0, 0, "", NAN, false, "the <15°> table is not a model"};
  EXPECT_NE(showcase_note(summary_json(v)).find("could not be compared with one on half of it: the &lt;15°&gt; table"),
            std::string::npos)
      << showcase_note(summary_json(v));
  auto s = summary_json(v);
  s.erase("default_grid_check");
  EXPECT_EQ(showcase_note(s).find("checked"), std::string::npos);
  EXPECT_EQ(showcase_note(s).find("converged"), std::string::npos);
}

// The status line names what decided it: a failing threshold with its error and grid.
TEST(FirstScreen, FailingThresholdIsNamedWithItsGrid) {
  auto v = distinct_runs();
  v.thresholds = {{{"F", 10.0, "", 1e-4}, 4e-4, false, v.runs[2].label()}};
  v.fail("threshold F");
  auto s = summary_json(v);
  const std::string first = first_screen_of(render_html(s, {}));
  EXPECT_NE(first.find("1 of 1 fail: F 0.04 % on the 10° grid (limit 0.01 %)"), std::string::npos) << first;
  // The headline, printed alone by the CLI, opens with the failure.
  s["status"] = "fail";
  EXPECT_EQ(headline(s).rfind("FAIL: threshold F. ", 0), 0u) << headline(s);
}

// None as accurate among the full runs: the speedup is a floor, against the ladder's most
// accurate run (not the reference's ratio, which flattered a --quick coarse grid 7×), said so on
// the screen, in the headline and in the baselines; without any completed full run the reference
// stands in; no recommended setting: no speedup anywhere on the screen.
TEST(FirstScreen, FloorWhenNoneAsAccurateReferenceStandsInNoSettingClaimsNothing) {
  auto v = distinct_runs();
  v.runs[0].errors.signals = {{"qdot", 1.0, 1e-3, 1e-3}, {"F", 1.0, 1e-3, 1e-3}};
  calc_first_screen(v);
  // 1e-10 run: ratios 5 and 2.5 to the recommended (2e-4, 4e-4); 1e-4 run (5e-4, 6e-4): 2.5, 1.5.
  ASSERT_EQ(v.recommended_full, 1);
  EXPECT_FALSE(v.recommended_full_as_accurate);
  ASSERT_TRUE(v.recommended_speedup);
  EXPECT_DOUBLE_EQ(*v.recommended_speedup, 0.3 / 0.003);
  auto s = summary_json(v);
  EXPECT_FALSE(s["recommended_full_as_accurate"].get<bool>());
  std::string first = first_screen_of(render_html(s, {}));
  EXPECT_NE(first.find("No run of the full-model ladder was as accurate"), std::string::npos) << first;
  EXPECT_NE(first.find("<b>100× faster</b> than it: at least"), std::string::npos) << first;
  EXPECT_NE(first.find("most accurate full run (less accurate)"), std::string::npos) << first;
  EXPECT_NE(headline(s).find("at least 100× faster at equal error"), std::string::npos) << headline(s);
  EXPECT_EQ(headline(s).find("1e+03×"), std::string::npos) << headline(s);

  for (auto& r : v.runs)
    if (r.model == "full") r.failure = "stopped";
  calc_first_screen(v);
  ASSERT_EQ(v.recommended_full, -1);
  ASSERT_TRUE(v.recommended_speedup);
  EXPECT_DOUBLE_EQ(*v.recommended_speedup, 3.0 / 0.003);  // the reference's 3 s
  first = first_screen_of(render_html(summary_json(v), {}));
  EXPECT_NE(first.find("against the reference"), std::string::npos) << first;
  EXPECT_NE(first.find("1e+03× faster"), std::string::npos) << first;

  v.recommended = -1;
  calc_first_screen(v);
  EXPECT_FALSE(v.recommended_speedup);
  s = summary_json(v);
  first = first_screen_of(render_html(s, {}));
  EXPECT_NE(first.find("No reduced run reached the target"), std::string::npos) << first;
  EXPECT_EQ(first.find("faster"), std::string::npos) << first;
  EXPECT_EQ(first.find("at the recommended setting"), std::string::npos) << first;
  EXPECT_NE(headline(s).find("no setting is recommended"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
