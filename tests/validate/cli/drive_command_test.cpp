// `rdyn drive` (validate/cli/drive_command.cpp): its outputs, statistics from rows at most 1°
// apart whatever --dt-out, and the command's contract.
#include "validate/cli/drive_command.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

TEST(DriveCommand, WritesItsOutputsAndKeepsTheContract) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rdyn_drive_cli_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto run = [&](std::vector<std::string> args) { return test::run_rdyn(args, dir); };
  // Statistics come from rows at most 1° apart whatever --dt-out: 0.5 s rows of a 1 rev/s run.
  auto r = run({"drive", RDYN_SCENES "/hard/parallelogram.yaml", "--cadence-hz", "1", "--duration", "2", "--dt-out",
                "0.5", "--model", "reduced", "--out", "coarse"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto c = nlohmann::json::parse(test::slurp(dir / "coarse" / "run.json"));
  const double kp = 9.81 * 0.18;
  EXPECT_NEAR(c["drive_peak"].get<double>(), kp, 1e-4 * kp);
  EXPECT_NEAR(c["drive_rms"].get<double>(), kp / std::sqrt(2.0), 1e-4 * kp);
  const std::string coarse = test::slurp(dir / "coarse" / "timeseries.csv");
  EXPECT_EQ(std::count(coarse.begin(), coarse.end(), '\n'), 6);  // header + 0, 0.5, 1, 1.5, 2
  r = run({"drive", "fourbar", "--cadence-hz", "2", "--out", "out"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(test::slurp(dir / "out" / "run.json"));
  EXPECT_EQ(j["drive_unit"], "N·m");
  EXPECT_DOUBLE_EQ(j["duration_s"].get<double>(), 0.5);  // one revolution by default
  EXPECT_TRUE(j["constraint_force_peaks_N"].contains("rocker_axial"));
  const std::string csv = test::slurp(dir / "out" / "timeseries.csv");
  EXPECT_EQ(csv.rfind("t,q,qdot,qddot,drive_Nm,drive_W,F_rocker_axial\n", 0), 0u);
  EXPECT_FALSE(j.contains("motor_check"));
  // --motor: run.json says whether the line covers the drive, and by how much (the margin's
  // closed form is the test above); the message says it in words.
  r = run({"drive", RDYN_SCENES "/hard/parallelogram.yaml", "--cadence-hz", "1", "--motor", "1,20", "--out", "weak"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto weak = nlohmann::json::parse(test::slurp(dir / "weak" / "run.json"))["motor_check"];
  EXPECT_FALSE(weak["covers"].get<bool>());
  EXPECT_NEAR(weak["min_margin"].get<double>(), 1 - 2 * M_PI / 20 - kp, 1e-3 * kp);
  EXPECT_NE(r.err.find("does NOT cover the drive"), std::string::npos) << r.err;
  // Bad input is exit 2 before any output: neither or both motions, a zero or infinite rate,
  // a constant rate for a slider, a missing profile.
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"drive", "fourbar", "--out", "o2"},
           {"drive", "fourbar", "--cadence-hz", "1", "--profile", "p.csv", "--out", "o2"},
           {"drive", "fourbar", "--cadence-hz", "0", "--out", "o2"},
           {"drive", "fourbar", "--cadence-hz", "inf", "--out", "o2"},
           {"drive", "slider-crank-slider", "--cadence-hz", "1", "--out", "o2"},
           {"drive", "fourbar", "--profile", "missing.csv", "--out", "o2"},
           {"drive", "fourbar", "--profile", "/dev/zero", "--out", "o2"},  // never ends: refused unread
           {"drive", "fourbar", "--cadence-hz", "1", "--duration", "0.5", "--dt-out", "1", "--out", "o2"},
           {"drive", "fourbar", "--cadence-hz", "1000", "--duration", "10", "--out", "o2"},  // hours of moves
           {"drive", "fourbar", "--cadence-hz", "1", "--motor", "5", "--out", "o2"},       // one number
           {"drive", "fourbar", "--cadence-hz", "1", "--motor", "5,-20", "--out", "o2"},   // two signs
           {"drive", "fourbar", "--cadence-hz", "1", "--motor", "0x5,20", "--out", "o2"},  // not decimal
           {"drive", "fourbar", "--cadence-hz", "1", "--motor", "5,0", "--out", "o2"}}) {
    r = run(args);
    EXPECT_EQ(r.status, 2) << args[2] << " " << r.err;
    EXPECT_FALSE(fs::exists(dir / "o2")) << args[2];
  }
  // What is too long or too short is named: a cadence whose one revolution makes too many rows,
  // profile rows 1e-300 s apart (was "--dt-out" and, for the profile, exit 1), a profile
  // shorter than one output interval.
  r = run({"drive", "fourbar", "--cadence-hz", "1e-9", "--out", "o2"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("field '--cadence-hz': one revolution at 1e-09 rev/s (1e+09 s)"), std::string::npos) << r.err;
  // One slow revolution within the row limit but too many projections for the full model: the
  // cadence is named (was "--duration", which was not given), with the rows that cost them.
  r = run({"drive", "fourbar", "--cadence-hz", "1e-3", "--out", "o2"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("field '--cadence-hz': the full model would make 5e+05 projections, one per computed row "
                       "(500001 over 1000 s"),
            std::string::npos)
      << r.err;
  // A given grid too coarse for the mechanism is warned in drive as in simulate (it was silent:
  // the Jansen leg's reactions 29 % off), and run.json has the table's half-grid miss.
  r = run({"drive", std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/jansen-leg.yaml", "--model", "reduced",
           "--cadence-hz", "1", "--grid-deg", "10", "--duration", "0.2", "--out", "jd"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("the 10° table looks too coarse for this mechanism"), std::string::npos) << r.err;
  {
    std::ifstream j(dir / "jd" / "run.json");
    const std::string json((std::istreambuf_iterator<char>(j)), std::istreambuf_iterator<char>());
    EXPECT_NE(json.find("\"table_m1_half_grid_miss\""), std::string::npos) << json;
  }
  // Too many rows at the output interval: raising --dt-out helps (the advice said "shorten").
  r = run({"drive", "fourbar", "--cadence-hz", "1", "--duration", "1e5", "--out", "o2"});
  EXPECT_NE(r.err.find("makes 5e+07 rows, more than 1e+07: shorten --duration or raise --dt-out"), std::string::npos)
      << r.err;
  r = run({"drive", "fourbar", "--cadence-hz", "1e-3", "--duration", "900", "--out", "o2"});
  EXPECT_NE(r.err.find("field '--duration': the full model would make"), std::string::npos) << r.err;
  {
    std::ofstream p(dir / "tiny.csv");
    p << "t,q_deg\n0,0\n1e-300,1\n2e-300,2\n3e-300,3\n";
    std::ofstream(dir / "short.csv") << "t,q_deg\n0,0\n1e-4,1\n2e-4,2\n3e-4,3\n";
  }
  r = run({"drive", "fourbar", "--profile", "short.csv", "--out", "o2"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("short.csv: field 't': the profile lasts 0.0003 s, shorter than --dt-out"), std::string::npos)
      << r.err;
  r = run({"drive", "fourbar", "--profile", "tiny.csv", "--out", "o2"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("tiny.csv:3: field 't': rows must be at least 1e-06 s apart"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "o2"));
  fs::remove_all(dir);
}

// A default grid is checked by the drive on half of it, as simulate checks its run: the bicycle's
// 10° knee line is interpolated 1.7e-3 off near the straight leg, so its drive is taken on 5°
// (within 1e-5 of the full model's); a given 10° stays, and is as far off as measured.
TEST(DriveCommand, ADefaultGridIsCheckedByTheDriveOnHalfIt) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rdyn_drive_grid_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  auto drive = [&](const std::string& model, const std::string& out, const std::vector<std::string>& more) {
    std::vector<std::string> args{"drive", "bicycle", "--cadence-hz", "1", "--model", model, "--out", out};
    args.insert(args.end(), more.begin(), more.end());
    const auto r = test::run_rdyn(args, dir);
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(test::slurp(dir / out / "run.json"));
  };
  const auto full = drive("full", "full", {}), checked = drive("reduced", "checked", {}),
             given = drive("reduced", "given", {"--grid-deg", "10"});
  EXPECT_EQ(checked["grid_deg"].get<double>(), 5);
  EXPECT_TRUE(checked["grid_check"]["verified"].get<bool>());
  EXPECT_EQ(checked["grid_check"]["coarser_grid_deg"].get<double>(), 10);
  EXPECT_FALSE(given.contains("grid_check"));
  const double peak = full["drive_peak"].get<double>(), knee = full["constraint_force_peaks_N"]["knee"].get<double>();
  EXPECT_NEAR(checked["drive_peak"].get<double>(), peak, 1e-5 * peak);
  EXPECT_NEAR(checked["constraint_force_peaks_N"]["knee"].get<double>(), knee, 1e-5 * knee);
  EXPECT_GT(std::abs(given["drive_peak"].get<double>() - peak), 1e-3 * peak);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate
