// Sweeps: the cartesian product of the axes, sharded into blocks whose CSVs concatenate.
#include "validate/analysis/sweep.hpp"
#include "validate/analysis/sweep_part.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <sstream>

#include <fmt/format.h>

#include "models/scene.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/cli/sweep_axis.hpp"
#include "tests/validate/analysis/jansen_text.hpp"

namespace rdyn::validate {
namespace {

// The shards, run apart (one thread each, in reverse order) and merged, are the whole sweep
// run at once in two threads, byte for byte; each shard's file names the sweep and its cases.
TEST(Sweep, MergedShardsAreTheWholeSweep) {
  SweepOptions o;
  o.scene = "bicycle";
  o.axes = {parse_sweep_axis("bicycle_leg.hip_torque_Nm=60:60:1"), parse_sweep_axis("bicycle_leg.crank_length_m=0.16:0.18:3")};
  o.threads = 2;
  const SweepResult r = run_sweep(o);
  const std::string& whole = r.csv;
  EXPECT_EQ(r.cases, 3);
  EXPECT_EQ(r.failed, 0);
  std::vector<SweepPart> parts;
  o.shards = 2;
  o.threads = 1;
  for (o.shard = 1; o.shard >= 0; --o.shard) {
    const SweepResult s = run_sweep(o);
    EXPECT_EQ(s.cases, o.shard == 0 ? 2 : 1);
    parts.push_back(parse_sweep_part(s.csv, fmt::format("part{}.csv", o.shard)));
    EXPECT_TRUE(parts.back().complete());
  }
  EXPECT_EQ(parts[1].id.sweep_hex, parts[0].id.sweep_hex);
  EXPECT_NE(parts[1].id.sweep_hex, parts[1].id.scene_hex);
  const MergedSweep m = merge_sweep_parts(parts);
  EXPECT_EQ(m.csv, whole);
  EXPECT_EQ(m.cases, 3);
  // metadata + header + 3 cases, all calibrated at 1 Hz, longer cranks needing less torque.
  EXPECT_EQ(whole.find("# rdyn-sweep v1 sweep="), 0u) << whole;
  EXPECT_NE(whole.find(" shard=0/1 cases=0-3/3\ncase,"), std::string::npos) << whole;
  EXPECT_EQ(std::count(whole.begin(), whole.end(), '\n'), 5);
  EXPECT_EQ(whole.find("error"), whole.find("error\n"));  // only the header's column name
  EXPECT_NE(whole.find(",status,drive_torque_Nm,"), std::string::npos) << whole;
  EXPECT_NE(whole.find(",peak_knee_force_N,"), std::string::npos) << whole;  // the scene's force name
  // Column 4 (case, two axes, status, torque): the torque falls as the crank lengthens.
  std::vector<double> torque;
  std::istringstream lines(whole);
  std::string line;
  std::getline(lines, line);  // metadata
  std::getline(lines, line);  // header
  while (std::getline(lines, line)) {
    std::istringstream cells(line);
    std::string cell;
    for (int c = 0; c <= 4; ++c) std::getline(cells, cell, ',');
    torque.push_back(std::stod(cell));
  }
  ASSERT_EQ(torque.size(), 3u);
  EXPECT_GT(torque[0], torque[1]);
  EXPECT_GT(torque[1], torque[2]);
}


}  // namespace
}  // namespace rdyn::validate

namespace rdyn::validate {
namespace {

// Keys are checked on the base scene at both ends of each axis before any case runs.
// Without --grid-deg and a scene grid, each case's table is 10° halved while it does not
// resolve m1, as calibrate's: the Jansen leg's (10° misses m1 by 10 %) is 2.5°, so its rows are
// those of a sweep given 2.5° (the first case cold, the second continued), bit for bit.
TEST(Sweep, ADefaultGridIsRefinedPerCaseAsCalibrateRefinesIt) {
  const std::string yaml = test::jansen_text_without_calibration_grid();
  ASSERT_FALSE(yaml.empty());
  const std::string path = ::testing::TempDir() + "jansen-no-grid.yaml";
  std::ofstream(path) << yaml;
  SweepOptions o;
  o.scene = path;
  o.axes = {parse_sweep_axis("bodies.crank.mass_kg=0.5:0.6:2")};
  o.threads = 1;
  auto rows = [](const std::string& csv) { return csv.substr(csv.find("\ncase,")); };  // after the fingerprint
  const SweepResult refined = run_sweep(o);
  EXPECT_EQ(refined.failed, 0) << refined.csv;
  o.grid_deg = 2.5;
  o.grid_given = true;
  const SweepResult given = run_sweep(o);
  EXPECT_EQ(rows(refined.csv), rows(given.csv));
  o.grid_deg = 10;
  const SweepResult coarse = run_sweep(o);
  EXPECT_NE(rows(refined.csv), rows(coarse.csv));
  std::remove(path.c_str());
}

TEST(Sweep, UnknownKeysAndOutOfRangeEndsFailBeforeWork) {
  SweepOptions o;
  o.scene = "fourbar";
  o.cadence_hz = 1.0;
  o.power_w = 1.0;
  o.axes = {parse_sweep_axis("no_such.key=1:2:3")};
  EXPECT_THROW(run_sweep(o), models::SceneError);
  o.axes = {parse_sweep_axis("bodies.crank.mass_kg=1:-1:3")};  // the far end is not a mass
  EXPECT_THROW(run_sweep(o), models::SceneError);
}

// A scene that cannot be calibrated at all (the four-bar has no drive torque) fails before
// any case runs.
TEST(Sweep, UncalibratableSceneFailsBeforeWork) {
  SweepOptions o;
  o.scene = "fourbar";
  o.cadence_hz = 1.0;
  o.power_w = 1.0;
  o.axes = {parse_sweep_axis("bodies.crank.mass_kg=0.4:0.6:3")};
  EXPECT_THROW(run_sweep(o), models::SceneError);
}

// Removes a temporary scene file however the test ends (a throwing run_sweep included).
struct RemoveOnExit {
  std::filesystem::path path;
  ~RemoveOnExit() {
    std::error_code ec;
    std::filesystem::remove(path, ec);
  }
};

// The shipped four-bar driven by a 0.5 N·m crank torque named "drive" (and `edit` applied to its
// text), as the text of a scene file.
template <typename Edit>
std::string driven_fourbar_yaml(Edit edit) {
  std::ifstream in(std::string(RDYN_SCENES) + "/fourbar.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  edit(yaml);
  yaml.replace(yaml.find("loads:\n"), 7, "loads:\n  - {type: joint_torque, name: drive, joint: crank, torque_Nm: 0.5}\n");
  return yaml;
}

// A failing case is a row with status "error" and its message, and it is counted: the
// four-bar driven by a crank torque, with the ground pivot D moved so far in the second case
// that the loop cannot close.
TEST(Sweep, FailingCasesAreCountedAndReported) {
  namespace fs = std::filesystem;
  const fs::path scene = fs::temp_directory_path() / ("rdyn_sweep_" + std::to_string(::getpid()) + ".yaml");
  const RemoveOnExit remove_scene{scene};
  std::ifstream in(std::string(RDYN_SCENES) + "/fourbar.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  yaml.replace(yaml.find("loads:\n"), 7, "loads:\n  - {type: joint_torque, name: drive, joint: crank, torque_Nm: 0.01}\n");
  std::ofstream(scene) << yaml;
  SweepOptions o;
  o.scene = scene.string();
  o.cadence_hz = 1.0;
  o.power_w = 0.01;
  o.sets = {"gravity.enabled=false"};  // no stall: the torque–cadence map is monotonic
  o.axes = {parse_sweep_axis("ground_points.D.0=0.30:3.0:2")};
  o.threads = 2;
  const SweepResult r = run_sweep(o);
  EXPECT_EQ(r.cases, 2);
  EXPECT_EQ(r.failed, 1) << r.csv;
  const auto header = r.csv.find('\n') + 1;  // after the metadata line
  const auto lines = r.csv.substr(r.csv.find('\n', header) + 1);
  EXPECT_EQ(lines.find("0,0.3,ok,"), 0u) << r.csv;                 // the first case calibrates
  EXPECT_NE(lines.find("1,3,error,,,,,,"), std::string::npos) << r.csv;  // the second names its loop
}

// A named load through the sweep: a flywheel's motor against viscous drag c, calibrated to a
// mean speed (no power): each row holds s = c·ω/(1 − ω/ω0) in a column named for the load's kind.
// The sweep's CSV lines after the metadata line (the header first), with every case expected
// to succeed.
std::vector<std::string> successful_rows(const SweepOptions& o) {
  const SweepResult r = run_sweep(o);
  EXPECT_EQ(r.failed, 0) << r.csv;
  std::vector<std::string> rows;
  std::istringstream lines(r.csv);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line.find("# rdyn-sweep v1 "), 0u) << line;
  while (std::getline(lines, line)) rows.push_back(line);
  return rows;
}

TEST(Sweep, NamedMotorLoadFollowsItsClosedForm) {
  namespace fs = std::filesystem;
  const fs::path scene = fs::temp_directory_path() / ("rdyn_sweep_motor_" + std::to_string(::getpid()) + ".yaml");
  const RemoveOnExit remove_scene{scene};
  std::ofstream(scene) << "name: flywheel\n"
                          "bodies: [{name: wheel, mass_kg: 2.0, inertia_kgm2: 0.05}]\n"
                          "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]\n"
                          "independent: wheel\n"
                          "loads:\n"
                          "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}\n"
                          "  - {type: motor, name: motor, joint: wheel, stall_torque_Nm: 1.0, no_load_speed_rad_s: 30}\n"
                          "initial: {q_deg: 0, qdot: 5.0}\n";
  SweepOptions o;
  o.scene = scene.string();
  o.cadence_hz = 2.0;
  o.load = "motor";
  // The wheel's inertia changes the mechanism (a new table); the drag coefficient does not (the
  // thread's last table is reused): neither changes the closed form, s = c·ω/(1 − ω/ω0).
  o.axes = {parse_sweep_axis("bodies.wheel.inertia_kgm2=0.05:0.1:2"), parse_sweep_axis("loads.drag.coefficient=0.01:0.03:3")};
  o.threads = 1;
  const auto rows = successful_rows(o);
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[0].find("case,bodies.wheel.inertia_kgm2,loads.drag.coefficient,status,motor_stall_torque_Nm,"), 0u)
      << rows[0];
  const double w = 2 * M_PI * 2.0;
  size_t k = 1;
  for (int inertia = 0; inertia < 2; ++inertia)
    for (double c : {0.01, 0.02, 0.03}) {
      const std::string& line = rows[k++];
      double s = 0;
      ASSERT_EQ(std::sscanf(line.substr(line.find(",ok,") + 4).c_str(), "%lf", &s), 1) << line;
      EXPECT_NEAR(s, c * w / (1 - w / 30.0), 1e-8) << line;
    }
}

// A drive sweep (--drive-cadence-hz) of a wheel whose centre of mass sits l = 0.1 m off its
// axle, with viscous drag c, turned at a constant ω from q = 0: drive = c ω + m g l cos q, so
// RMS² = (cω)² + (m g l)²/2, peak = c ω + m g l (the row at q = 0), mean = c ω, mean power c ω².
// The inertia changes the mechanism (another table) but not the drive at a constant rate.
TEST(Sweep, DriveSweepFollowsItsClosedForm) {
  namespace fs = std::filesystem;
  const fs::path scene = fs::temp_directory_path() / ("rdyn_sweep_drive_" + std::to_string(::getpid()) + ".yaml");
  const RemoveOnExit remove_scene{scene};
  std::ofstream(scene) << "name: eccentric-wheel\n"
                          "bodies: [{name: wheel, mass_kg: 2.0, com_m: [0.1, 0], inertia_kgm2: 0.05}]\n"
                          "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]\n"
                          "independent: wheel\n"
                          "loads:\n"
                          "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}\n"
                          "gravity: {enabled: true, g_m_s2: [0, -9.81]}\n"
                          "initial: {q_deg: 0, qdot: 5.0}\n";
  SweepOptions o;
  o.scene = scene.string();
  o.drive_cadence_hz = 1.5;
  o.axes = {parse_sweep_axis("bodies.wheel.inertia_kgm2=0.05:0.1:2"), parse_sweep_axis("loads.drag.coefficient=0.01:0.03:3")};
  o.threads = 2;
  const auto rows = successful_rows(o);
  ASSERT_EQ(rows.size(), 7u);
  EXPECT_EQ(rows[0], "case,bodies.wheel.inertia_kgm2,loads.drag.coefficient,status,drive_rms_Nm,drive_peak_Nm,"
                     "drive_mean_Nm,mean_power_w,peak_power_w,peak_constraint_force_N,error");
  const double w = 2 * M_PI * 1.5, mgl = 2.0 * 9.81 * 0.1;
  size_t k = 1;
  for (int inertia = 0; inertia < 2; ++inertia)
    for (double c : {0.01, 0.02, 0.03}) {
      const std::string& line = rows[k++];
      double rms = 0, peak = 0, mean = 0, power = 0, peak_power = 0;
      ASSERT_EQ(std::sscanf(line.substr(line.find(",ok,") + 4).c_str(), "%lf,%lf,%lf,%lf,%lf", &rms, &peak, &mean,
                            &power, &peak_power),
                5)
          << line;
      // A 10° Fourier table of a constant m1 and cos q: exact to rounding; the trapezoidal
      // rule over a whole period integrates cos² exactly.
      EXPECT_NEAR(rms, std::sqrt(c * w * c * w + mgl * mgl / 2), 1e-8) << line;
      EXPECT_NEAR(peak, c * w + mgl, 1e-8) << line;
      EXPECT_NEAR(mean, c * w, 1e-8) << line;
      EXPECT_NEAR(power, c * w * w, 1e-7) << line;
      EXPECT_NEAR(peak_power, (c * w + mgl) * w, 1e-7) << line;
      EXPECT_NE(line.find(",ok,"), std::string::npos);
      EXPECT_EQ(line.back(), ',');  // no error message, no force requested: an empty field
    }
  // A case alone (the Python module's map) is the row the threaded sweep wrote.
  const SweepPlan plan = plan_sweep(o);
  EXPECT_EQ(run_sweep_case(plan, 4), rows[5]);
  EXPECT_THROW(run_sweep_case(plan, 6), models::SceneError);
  // Its shards merge into the whole sweep (its header has one result column more than a
  // calibrating sweep's: --merge and --resume refused every drive part).
  const SweepResult whole = run_sweep(o);
  std::vector<SweepPart> parts;
  for (int i = 0; i < 3; ++i) {
    SweepOptions shard = o;
    shard.shard = i;
    shard.shards = 3;
    parts.push_back(parse_sweep_part(run_sweep(shard).csv, "part" + std::to_string(i) + ".csv"));
  }
  const MergedSweep merged = merge_sweep_parts(parts);
  EXPECT_EQ(merged.cases, 6);
  EXPECT_EQ(merged.csv.substr(merged.csv.find('\n')), whole.csv.substr(whole.csv.find('\n')));
  // A drive sweep calibrates nothing: with a calibration option it is refused before work.
  SweepOptions both = o;
  both.cadence_hz = 1.0;
  try {
    plan_sweep(both);
    ADD_FAILURE() << "a drive sweep with --cadence-hz was accepted";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "--drive-cadence-hz") << e.what();
  }
}

// A calibrating sweep's case alone is its row in the sweep (the Python module maps over them).
TEST(Sweep, ACaseAloneIsItsRowInTheSweep) {
  SweepOptions o;
  o.scene = "bicycle";
  o.axes = {parse_sweep_axis("bicycle_leg.crank_length_m=0.16:0.18:2")};
  o.threads = 1;
  const auto rows = successful_rows(o);
  ASSERT_EQ(rows.size(), 3u);
  const SweepPlan plan = plan_sweep(o);
  EXPECT_EQ(run_sweep_case(plan, 0), rows[1]);
  EXPECT_EQ(run_sweep_case(plan, 1), rows[2]);
}

// The loops' branch checks are not in the scene hash (they only refuse an assembly): a case
// whose check fails is an error row whatever case ran before it in the thread, never a reused
// table of the other branch.
TEST(Sweep, ABranchCheckIsNeverSkippedByAReusedTable) {
  namespace fs = std::filesystem;
  const std::string yaml = driven_fourbar_yaml([](std::string& y) {
    y.replace(y.find("point_b: C}"), 11, "point_b: C, branch: {joint: rocker, sign: positive}}");
  });
  const fs::path scene = fs::temp_directory_path() / ("rdyn_sweep_branch_" + std::to_string(::getpid()) + ".yaml");
  const RemoveOnExit remove_scene{scene};
  std::ofstream(scene) << yaml;
  SweepOptions o;
  o.scene = scene.string();
  o.cadence_hz = 1.0;
  o.load = "drive";
  o.threads = 1;
  for (const char* axis : {"loops.C.branch.sign=1:-1:2", "loops.C.branch.sign=-1:1:2"}) {
    o.axes = {parse_sweep_axis(axis)};
    const SweepResult r = run_sweep(o);
    EXPECT_EQ(r.failed, 1) << axis << "\n" << r.csv;
    std::istringstream lines(r.csv);
    std::string line;
    std::getline(lines, line);  // metadata
    std::getline(lines, line);  // header
    while (std::getline(lines, line)) {
      const bool negative = line.find(",-1,") != std::string::npos;
      EXPECT_EQ(line.find(",error,") != std::string::npos, negative) << axis << ": " << line;
    }
  }
}

// A case on a reused table is the case calibrated on its own: a bicycle sweep over the rider's
// height (a new table each) and the resistance's power (a value: the thread's table is reused)
// against calibrate() of each scene, to the last digit the CSV prints.
TEST(Sweep, ReusedTableGivesTheCaseItsOwnCalibration) {
  SweepOptions o;
  o.scene = "bicycle";
  o.axes = {parse_sweep_axis("bicycle_leg.subject.height_m=1.7:1.8:2"),
            parse_sweep_axis("bicycle_leg.resistance.power_W=100:150:2")};
  o.threads = 1;
  const auto rows = successful_rows(o);
  ASSERT_EQ(rows.size(), 5u);
  size_t k = 1;
  for (double h : {1.7, 1.8})
    for (double p : {100.0, 150.0}) {
      const std::string& line = rows[k++];
      const auto scene = models::load_scene(
          "bicycle", {{"bicycle_leg.subject.height_m", fmt::format("{:.17g}", h)},
                      {"bicycle_leg.resistance.power_W", fmt::format("{:.17g}", p)}});
      CalibrationOptions opt = calibration_options_of(scene, 0.0, 0.0, "");
      opt.full_max_s = 0.0;
      Progress quiet(false);
      const auto own = calibrate(scene, opt, quiet);
      EXPECT_NE(line.find(fmt::format(",ok,{:.10g},", own.load_value)), std::string::npos)
          << line << " vs " << own.load_value;
    }
}


// The cases of one mechanism run one after the other whatever the order of --vary: with the
// rider's height (a new table) as the last, fastest axis, one thread extracts two tables for
// four cases, not four, and each row holds what the other axis order gives for its case.
TEST(Sweep, CasesOfOneMechanismRunTogetherWhateverTheAxisOrder) {
  SweepOptions o;
  o.scene = "bicycle";
  o.threads = 1;
  o.axes = {parse_sweep_axis("bicycle_leg.resistance.power_W=100:150:2"),
            parse_sweep_axis("bicycle_leg.subject.height_m=1.7:1.8:2")};
  const SweepPlan plan = plan_sweep(o);
  EXPECT_EQ(plan.changes_mechanism, (std::vector<bool>{false, true}));
  const SweepResult height_last = run_sweep(plan, nullptr);
  EXPECT_EQ(height_last.tables, 2);
  EXPECT_EQ(height_last.failed, 0) << height_last.csv;
  std::swap(o.axes[0], o.axes[1]);
  const SweepResult height_first = run_sweep(o);
  EXPECT_EQ(height_first.tables, 2);
  // Row (p, h) of the first against row (h, p) of the second, from the status on.
  auto rows_of = [](const std::string& csv) {
    std::vector<std::string> rows;
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);  // metadata
    std::getline(lines, line);  // header
    while (std::getline(lines, line)) rows.push_back(line.substr(line.find(",ok,")));
    return rows;
  };
  const auto a = rows_of(height_last.csv), b = rows_of(height_first.csv);
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), 4u);
  for (int p = 0; p < 2; ++p)
    for (int h = 0; h < 2; ++h) EXPECT_EQ(a[2 * p + h], b[2 * h + p]) << p << " " << h;
}

// Two threads take whole mechanisms while there are at least 4 per thread (3 powers × 8 heights:
// chunks of up to 24/8 = 3 cases): each of the 8 tables is extracted once, and the file is the
// one thread's, byte for byte.
TEST(Sweep, ThreadsTakeWholeMechanismsAndWriteTheSameFile) {
  SweepOptions o;
  o.scene = "bicycle";
  o.axes = {parse_sweep_axis("bicycle_leg.resistance.power_W=100:150:3"),
            parse_sweep_axis("bicycle_leg.subject.height_m=1.6:1.9:8")};
  o.threads = 2;
  const SweepResult two = run_sweep(o);
  EXPECT_EQ(two.threads, 2);
  EXPECT_EQ(two.tables, 8);
  EXPECT_EQ(two.failed, 0) << two.csv;
  o.threads = 1;
  const SweepResult one = run_sweep(o);
  EXPECT_EQ(one.tables, 8);
  EXPECT_EQ(two.csv, one.csv);
}

// Continuation in the parameters (issue #28 item 3): over the rider's height one thread walks
// for its first table only (each next one continues from its neighbour, far from dead points),
// and every row is calibrate() of its own scene run cold, to the last digit the CSV prints.
TEST(Sweep, ContinuedCasesAreTheColdCases) {
  SweepOptions o;
  o.scene = "bicycle";
  o.axes = {parse_sweep_axis("bicycle_leg.subject.height_m=1.6:1.9:4")};
  o.threads = 1;
  const SweepResult r = run_sweep(o);
  EXPECT_EQ(r.failed, 0) << r.csv;
  EXPECT_EQ(r.tables, 4);
  EXPECT_EQ(r.walks, 1);
  std::istringstream lines(r.csv);
  std::string line;
  std::getline(lines, line);  // metadata
  std::getline(lines, line);  // header
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(std::getline(lines, line));
    const auto scene =
        models::load_scene("bicycle", {{"bicycle_leg.subject.height_m", fmt::format("{:.17g}", o.axes[0].values[k])}});
    CalibrationOptions opt = calibration_options_of(scene, 0.0, 0.0, "");
    opt.full_max_s = 0.0;
    Progress quiet(false);
    const auto cold = calibrate(scene, opt, quiet);
    EXPECT_EQ(line.substr(line.find(",ok,")),
              fmt::format(",ok,{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},", cold.load_value,
                          cold.mean_cadence_hz_reduced, cold.mean_power_w, cold.peak_force_N, cold.speed_fluctuation))
        << k;
  }
  // Two threads: each walks for its first table; the file is the one thread's, byte for byte.
  o.threads = 2;
  const SweepResult two = run_sweep(o);
  EXPECT_EQ(two.csv, r.csv);
}

// A case near a dead point after a neighbour that turned freely is refused as cold: the
// four-bar of Calibrate.ANarrowBlockedRangeIsRefused (20° grid from −158°, where only the walk
// finds the blocked range) after a shorter crank, in one thread.
TEST(Sweep, ACaseNearADeadPointIsRefusedAfterAFreeNeighbour) {
  namespace fs = std::filesystem;
  const std::string yaml = driven_fourbar_yaml([](std::string&) {});
  const fs::path scene = fs::temp_directory_path() / ("rdyn_sweep_blocked_" + std::to_string(::getpid()) + ".yaml");
  const RemoveOnExit remove_scene{scene};
  std::ofstream(scene) << yaml;
  SweepOptions o;
  o.scene = scene.string();
  o.cadence_hz = 1.0;
  o.load = "drive";
  o.grid_deg = 20;
  o.threads = 1;
  o.sets = {"ground_points.D.0=0.299714", "ground_points.D.1=0.013089", "initial.q_deg=-158"};
  o.axes = {parse_sweep_axis("bodies.crank.points.B.0=0.15:0.18004:2")};
  auto last_row = [](const std::string& csv) {
    const std::string body = csv.substr(0, csv.size() - 1);
    return body.substr(body.rfind('\n') + 1);
  };
  const SweepResult r = run_sweep(o);
  EXPECT_EQ(r.tables, 2);
  const std::string blocked = last_row(r.csv);
  EXPECT_EQ(blocked.find("1,0.18004,error,"), 0u) << r.csv;
  EXPECT_NE(blocked.find("dead points"), std::string::npos) << r.csv;
  // The same case alone (no neighbour): the same row but its case number.
  o.axes = {parse_sweep_axis("bodies.crank.points.B.0=0.18004:0.18004:1")};
  const std::string alone = last_row(run_sweep(o).csv);
  EXPECT_EQ(blocked.substr(1), alone.substr(1)) << alone;
}

}  // namespace
}  // namespace rdyn::validate
