// The validate report's drive figure: drawn from the summary's drive_cycle record alone, its
// numbers in the table as the record holds them, the figure rendered by gnuplot.
#include "validate/report/drive_figure.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

#include "tests/validate/harness/validation_fixture.hpp"
#include "tests/validate/run_rdyn.hpp"
#include "validate/harness/summary.hpp"
#include "validate/report/report.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

// A drive cycle of k cos q (full) and k cos q + 0.01 (reduced) on 1° rows, k = 2 N·m.
DriveCycleComparison cosine_cycle() {
  DriveCycleComparison c;
  c.cadence_hz = 1.0;
  for (int i = 0; i <= 360; ++i) {
    const double q = i * M_PI / 180;
    c.full.t.push_back(i / 360.0), c.full.q.push_back(q), c.full.drive.push_back(2 * std::cos(q));
    c.full.power.push_back(c.full.drive.back() * 2 * M_PI);
  }
  c.reduced = c.full;
  for (double& d : c.reduced.drive) d += 0.01;
  c.full_stats = calc_drive_stats(c.full);
  c.reduced_stats = calc_drive_stats(c.reduced);
  c.max_difference = 0.01;
  c.rms_difference = 0.01;
  return c;
}

TEST(DriveFigure, CsvScriptAndSectionFromTheRecord) {
  auto v = test::synthetic_validation();
  v.drive_cycle = cosine_cycle();
  const auto record = summary_json(v).at("drive_cycle");
  const std::string csv = drive_cycle_csv(record);
  EXPECT_EQ(csv.rfind("q_deg,t,drive_full_Nm,drive_reduced_Nm\n0,0,2,2.01\n", 0), 0u) << csv.substr(0, 80);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 362);
  EXPECT_NE(csv.find("\n180,0.5,-2,-1.99\n"), std::string::npos);
  const std::string gp = drive_cycle_gp(record);
  EXPECT_NE(gp.find("set output 'drive.svg'"), std::string::npos);
  EXPECT_NE(gp.find("using 1:($4-$3)"), std::string::npos);  // the difference panel
  // RMS of 2 cos q over a turn: √2 (trapezoidal rule, exact for cos² over whole periods).
  const std::string h = drive_cycle_section(record, {{"drive", "<svg>the figure</svg>"}});
  EXPECT_NE(h.find("<svg>the figure</svg>"), std::string::npos);
  EXPECT_NE(h.find("<tr><td class=l>RMS drive [N·m]</td><td>1.414</td><td>1.414</td>"), std::string::npos) << h;
  EXPECT_NE(h.find("<td class=l>peak |drive| [N·m]</td><td>2</td><td>2.01</td><td>+0.01</td>"), std::string::npos)
      << h;
  EXPECT_NE(h.find("0.5 % of the full model's peak"), std::string::npos) << h;
  EXPECT_NE(drive_cycle_section(record, {}).find("drive.svg could not be rendered"), std::string::npos);
}

TEST(DriveFigure, TheReportDrawsItAndReRendersItFromTheSummary) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_drive_figure_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  auto v = test::synthetic_validation();
  v.drive_cycle = cosine_cycle();
  render_report(summary_json(v), (dir / "a").string());
  render_report(nlohmann::json::parse(test::slurp(dir / "a" / "summary.json")), (dir / "b").string());
  for (const char* f : {"drive.csv", "drive.gp", "report.html"})
    EXPECT_EQ(test::slurp(dir / "a" / f), test::slurp(dir / "b" / f)) << f;
  const std::string html = test::slurp(dir / "b" / "report.html");
  EXPECT_NE(html.find("<h2>Drive at the scene's cadence</h2>"), std::string::npos);
  EXPECT_EQ(html.find("drive.svg could not be rendered"), std::string::npos) << test::slurp(dir / "b" / "gnuplot.log");
  EXPECT_TRUE(fs::exists(dir / "b" / "drive.svg"));
  // Without the record: no section, no files.
  fs::create_directories(dir / "c");
  render_report(summary_json(test::synthetic_validation()), (dir / "c").string());
  EXPECT_FALSE(fs::exists(dir / "c" / "drive.csv"));
  EXPECT_EQ(test::slurp(dir / "c" / "report.html").find("Drive at the scene"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate
