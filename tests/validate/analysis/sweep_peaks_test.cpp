// `rdyn sweep --peak COLUMN`: peaks of any output column of a case's reduced run, checked before
// any case runs, against closed forms (a wheel's pivot reaction), against the sweep's own peak
// columns (two routes), and through shards and merges.
#include "validate/analysis/sweep_peaks.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "models/scene_yaml.hpp"
#include "reduced/reduced_model.hpp"
#include "validate/analysis/sweep.hpp"
#include "validate/analysis/sweep_part.hpp"
#include "validate/cli/sweep_axis.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

// A wheel of mass m whose centre of mass sits l = 0.1 m off its axle, driven by a joint torque
// against viscous drag; `extra` is appended (gravity, outputs).
struct WheelScene {
  fs::path path;
  explicit WheelScene(const std::string& extra) {
    path = fs::temp_directory_path() /
           ("rdyn_sweep_peaks_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".yaml");
    std::ofstream(path) << "name: wheel\n"
                           "bodies: [{name: wheel, mass_kg: 2.0, com_m: [0.1, 0], inertia_kgm2: 0.05}]\n"
                           "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], child: wheel}]\n"
                           "independent: wheel\n"
                           "loads:\n"
                           "  - {type: joint_torque, name: drive, joint: wheel, torque_Nm: 0.5}\n"
                           "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}\n"
                           "initial: {q_deg: 0, qdot: 5.0}\n"
                        << extra;
  }
  ~WheelScene() {
    std::error_code ec;
    fs::remove(path, ec);
  }
};

// The sweep's rows (header first, metadata dropped) as maps from column name to field; every
// case must succeed (their rows hold no quoted field).
std::vector<std::map<std::string, std::string>> rows_of(const std::string& csv) {
  std::istringstream lines(csv);
  std::string line;
  std::getline(lines, line);  // metadata
  auto split = [](const std::string& l) {
    std::vector<std::string> f;
    std::stringstream cells(l);
    std::string cell;
    while (std::getline(cells, cell, ',')) f.push_back(cell);
    if (!l.empty() && l.back() == ',') f.push_back("");
    return f;
  };
  std::getline(lines, line);
  const auto header = split(line);
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(lines, line)) {
    const auto f = split(line);
    EXPECT_EQ(f.size(), header.size()) << line;
    std::map<std::string, std::string> row;
    for (size_t k = 0; k < f.size() && k < header.size(); ++k) row[header[k]] = f[k];
    EXPECT_EQ(row["status"], "ok") << line;
    rows.push_back(row);
  }
  return rows;
}

double num(std::map<std::string, std::string>& row, const std::string& column) {
  EXPECT_EQ(row.count(column), 1u) << column;
  return std::stod(row[column]);
}

// What plan_sweep says about --peak names (the SceneError's field and message; "" accepted).
std::string refusal(SweepOptions o, std::vector<std::string> peaks) {
  o.peaks = std::move(peaks);
  try {
    plan_sweep(o);
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "--peak") << e.what();
    return e.message();
  }
  return "";
}

TEST(SweepPeaks, ColumnsAreCheckedBeforeAnyCaseRuns) {
  const WheelScene wheel("outputs: {constraint_forces: [{name: pin, joint: wheel, direction: [1, 0]}]}\n");
  SweepOptions o;
  o.scene = wheel.path.string();
  o.cadence_hz = 1.0;
  o.load = "drive";
  o.axes = {parse_sweep_axis("loads.drag.coefficient=0.01:0.02:2")};
  EXPECT_EQ(refusal(o, {"F_pin", "qdot", "energy"}), "");
  // An unknown name lists the columns there are.
  const std::string unknown = refusal(o, {"F_knee"});
  EXPECT_NE(unknown.find("no column 'F_knee'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("this sweep's columns: q, qdot, qddot, energy, work, F_pin"), std::string::npos) << unknown;
  // A joint output the scene does not request names the key that does.
  const std::string reaction = refusal(o, {"R_wheel_y"});
  EXPECT_NE(reaction.find("not requested by the scene: add it with outputs.reactions"), std::string::npos) << reaction;
  EXPECT_NE(refusal(o, {"shaking_M"}).find("outputs.shaking: true"), std::string::npos);
  EXPECT_NE(refusal(o, {"qdot_wheel"}).find("outputs.joints"), std::string::npos);
  EXPECT_NE(refusal(o, {"R_hub_x"}).find("no column 'R_hub_x'"), std::string::npos);  // no joint hub
  EXPECT_NE(refusal(o, {"qdot", "qdot"}).find("named twice"), std::string::npos);
  EXPECT_NE(refusal(o, {"t"}).find("not a peak"), std::string::npos);
  // drive_Nm is a drive sweep's column, not a calibrating sweep's.
  EXPECT_NE(refusal(o, {"drive_Nm"}).find("no column 'drive_Nm'"), std::string::npos);
  SweepOptions d = o;
  d.cadence_hz = 0, d.load.clear(), d.drive_cadence_hz = 1.0;
  EXPECT_EQ(refusal(d, {"drive_Nm", "drive_W", "F_pin"}), "");
}

TEST(SweepPeaks, ColumnPeaksAreTheLargestMagnitudeAndNeverNaN) {
  const std::vector<double> a{1.0, -3.0, 2.0}, b{0.5, 0.25, -0.125}, bad{0.0, NAN, 1.0};
  const std::vector<std::string> names{"a", "b", "bad"};
  auto column = [&](size_t k) -> const std::vector<double>& { return k == 0 ? a : k == 1 ? b : bad; };
  const auto p = calc_column_peaks(names, column, {"b", "a"});
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0], 0.5);
  EXPECT_EQ(p[1], 3.0);
  EXPECT_THROW(calc_column_peaks(names, column, {"bad"}), models::NumericalError);
  EXPECT_THROW(calc_column_peaks(names, column, {"c"}), std::invalid_argument);
}

// Without gravity the calibrated wheel turns at a constant ω = 2πF (its m1 is constant, the
// torque balances the drag): the pivot pulls its centre of mass round, |R| = m l ω² along the
// crank, so the peaks of R_x, R_y, shaking_x and shaking_y are all m l ω² (the cycle starts at
// q = 0, where R is along x), q̇ peaks at ω and q̈ is 0. The other columns are those of the
// same sweep without --peak (its table carries reaction lines the calibration does not read).
// A case's table columns: its reduced model's, and with a joint-output peak also the joint columns
// (p_, k_, r_ of every joint) beside the reaction lines that peak_table_scene adds; without one,
// the scene's own joint outputs are not read by any case and not kept.
TEST(SweepPeaks, TheTableKeepsTheJointColumnsOnlyForJointOutputPeaks) {
  const WheelScene wheel("gravity: {enabled: false}\noutputs: {reactions: [wheel], shaking: true}\n");
  const auto scene = models::load_scene(wheel.path.string());
  auto has = [](const std::vector<std::string>& v, const std::string& s) {
    return std::find(v.begin(), v.end(), s) != v.end();
  };
  const auto plain = sweep_table_columns(scene, {"qdot"});
  EXPECT_EQ(plain, reduced::reduced_model_columns(scene));
  EXPECT_FALSE(has(plain, "p_wheel"));
  const auto joint = sweep_table_columns(scene, {"R_wheel_x"});
  for (const char* c : {"m1", "r_wheel", "w_wheel", "p_wheel", "k_wheel"}) EXPECT_TRUE(has(joint, c)) << c;
  for (const auto& f : peak_table_scene(scene, {"R_wheel_x"}).outputs.constraint_forces)
    EXPECT_TRUE(has(joint, "me1_" + f.name)) << f.name;
}

TEST(SweepPeaks, CalibratedWheelReactionsFollowTheirClosedForm) {
  const WheelScene wheel("gravity: {enabled: false}\noutputs: {reactions: [wheel], shaking: true}\n");
  SweepOptions o;
  o.scene = wheel.path.string();
  o.cadence_hz = 1.25;
  o.load = "drive";
  o.threads = 2;
  o.axes = {parse_sweep_axis("bodies.wheel.mass_kg=1:3:3")};
  const std::string plain = run_sweep(o).csv;
  o.peaks = {"R_wheel_x", "R_wheel_y", "shaking_x", "shaking_y", "qdot", "qddot"};
  const SweepResult r = run_sweep(o);
  ASSERT_EQ(r.failed, 0) << r.csv;
  auto rows = rows_of(r.csv), plain_rows = rows_of(plain);
  ASSERT_EQ(rows.size(), 3u);
  const double w = 2 * M_PI * 1.25;
  for (size_t k = 0; k < rows.size(); ++k) {
    auto& row = rows[k];
    const double m = num(row, "bodies.wheel.mass_kg"), R = m * 0.1 * w * w;
    for (const char* c : {"peak_R_wheel_x", "peak_R_wheel_y", "peak_shaking_x", "peak_shaking_y"})
      EXPECT_NEAR(num(row, c), R, 1e-8 * R) << c << " at m = " << m;
    EXPECT_NEAR(num(row, "peak_qdot"), w, 1e-8 * w);
    EXPECT_LT(num(row, "peak_qddot"), 1e-6 * w * w);
    for (const auto& [column, value] : plain_rows[k]) EXPECT_EQ(row[column], value) << column;
  }
}

// A drive sweep of the same wheel under gravity at a constant ω: R = m (a_c − g), a_c = −ω² l
// (cos q, sin q), so |R_x| peaks at m ω² l (q = 0) and |R_y| at m (ω² l + g) (q = 270°, a row:
// the rows are 1° apart); the shaking load is −R. Its peak of drive_Nm is the drive_peak_Nm
// column. Shards with --peak merge into the whole sweep byte for byte; a part written with
// other --peak columns is another sweep and does not merge.
TEST(SweepPeaks, DriveSweepPeaksFollowTheirClosedFormAndMerge) {
  const WheelScene wheel("gravity: {enabled: true, g_m_s2: [0, -9.81]}\noutputs: {reactions: [wheel], shaking: true}\n");
  SweepOptions o;
  o.scene = wheel.path.string();
  o.drive_cadence_hz = 1.5;
  o.threads = 2;
  o.axes = {parse_sweep_axis("bodies.wheel.mass_kg=1:2:2"), parse_sweep_axis("loads.drag.coefficient=0.01:0.03:2")};
  o.peaks = {"R_wheel_x", "R_wheel_y", "shaking_y", "drive_Nm"};
  const SweepResult whole = run_sweep(o);
  ASSERT_EQ(whole.failed, 0) << whole.csv;
  const double w = 2 * M_PI * 1.5;
  for (auto& row : rows_of(whole.csv)) {
    const double m = num(row, "bodies.wheel.mass_kg");
    EXPECT_NEAR(num(row, "peak_R_wheel_x"), m * w * w * 0.1, 1e-8 * m * w * w);
    EXPECT_NEAR(num(row, "peak_R_wheel_y"), m * (w * w * 0.1 + 9.81), 1e-8 * m * w * w);
    EXPECT_NEAR(num(row, "peak_shaking_y"), m * (w * w * 0.1 + 9.81), 1e-8 * m * w * w);
    EXPECT_EQ(row["peak_drive_Nm"], row["drive_peak_Nm"]);
  }
  std::vector<SweepPart> parts;
  for (int i = 0; i < 2; ++i) {
    SweepOptions shard = o;
    shard.shard = i, shard.shards = 2, shard.threads = 1;
    parts.push_back(parse_sweep_part(run_sweep(shard).csv, "part" + std::to_string(i) + ".csv"));
  }
  EXPECT_EQ(merge_sweep_parts(parts).csv, whole.csv);
  SweepOptions other = o;
  other.peaks = {"R_wheel_x"};
  other.shard = 1, other.shards = 2;
  parts[1] = parse_sweep_part(run_sweep(other).csv, "other.csv");
  try {
    merge_sweep_parts(parts);
    ADD_FAILURE() << "parts with different --peak columns merged";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.file(), "other.csv") << e.what();
  }
}

// The bicycle's knee force two ways: the sweep's peak_knee_force_N (the steady cycle's samples
// refined by golden section) and peak_F_knee (the maximum over kPeakCycleRows rows of a time
// integration of that cycle): the same to the rows' sampling error (~1e-5 of the peak).
TEST(SweepPeaks, PeakOfTheKneeForceColumnIsTheSweepsPeakForce) {
  SweepOptions o;
  o.scene = "bicycle";
  o.threads = 1;
  o.axes = {parse_sweep_axis("bicycle_leg.crank_length_m=0.17:0.17:1")};
  o.peaks = {"F_knee", "qdot"};
  auto rows = rows_of(run_sweep(o).csv);
  ASSERT_EQ(rows.size(), 1u);
  const double refined = num(rows[0], "peak_knee_force_N"), sampled = num(rows[0], "peak_F_knee");
  EXPECT_LE(sampled, refined * (1 + 1e-9));
  EXPECT_NEAR(sampled, refined, 1e-4 * refined);
  // q̇ at its peak exceeds the mean speed 2πF by the speed fluctuation's upper half at most.
  const double mean = 2 * M_PI * num(rows[0], "mean_cadence_hz"), fluct = num(rows[0], "speed_fluctuation");
  EXPECT_GT(num(rows[0], "peak_qdot"), mean);
  EXPECT_LT(num(rows[0], "peak_qdot"), mean * (1 + fluct));
}

}  // namespace
}  // namespace rdyn::validate
