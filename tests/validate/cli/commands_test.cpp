// The subcommands of validate/cli/commands.cpp end to end (simulate, extract, calibrate, validate,
// sweep): outputs, exit statuses and messages on bad input. Help and dispatch: main_test.cpp.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string output;  // stdout + stderr
};

CliRun rdyn(const std::string& args) {
  const std::string cmd = std::string(RDYN_BINARY) + " " + args + " 2>&1";
  CliRun r{-1, ""};
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) r.output.append(buf.data(), n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

// Every column of a timeseries.csv, by name.
std::map<std::string, std::vector<double>> read_columns(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);
  std::vector<std::string> names;
  for (size_t a = 0, b; a <= line.size(); a = b + 1) {
    b = std::min(line.find(',', a), line.size());
    names.push_back(line.substr(a, b - a));
  }
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(f, line))
    for (size_t a = 0, b, k = 0; a <= line.size() && k < names.size(); a = b + 1, ++k) {
      b = std::min(line.find(',', a), line.size());
      cols[names[k]].push_back(std::stod(line.substr(a, b - a)));
    }
  return cols;
}

// max |run − ref| / max |ref| (the two series of one length).
double max_rel_difference(const std::vector<double>& ref, const std::vector<double>& run) {
  double peak = 0, d = 0;
  for (size_t i = 0; i < ref.size() && i < run.size(); ++i) {
    peak = std::max(peak, std::abs(ref[i]));
    d = std::max(d, std::abs(run[i] - ref[i]));
  }
  return d / peak;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rdyn_cli_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  // `rdyn simulate ARGS --out <dir>/NAME` (status 0 expected): one column of its timeseries.csv;
  // `said` gets what it printed.
  std::vector<double> simulated(const std::string& args, const std::string& name, const std::string& column,
                                std::string* said = nullptr) {
    const CliRun r = rdyn("simulate " + args + " --out " + (dir_ / name).string());
    EXPECT_EQ(r.status, 0) << r.output;
    if (said) *said = r.output;
    return read_columns(dir_ / name / "timeseries.csv")[column];
  }
  // Bad input: status 2, a message naming `file`, and no output folder left behind.
  void expect_refused(const std::string& args, const std::string& file) {
    const auto out = dir_ / "out";
    const CliRun r = rdyn(args + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << r.output;
    EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << args;
    for (const auto& e : fs::directory_iterator(dir_))
      EXPECT_EQ(e.path().filename().string().find(".out.tmp"), std::string::npos) << "temporary left behind";
  }
  fs::path dir_;
};

TEST_F(Cli, SimulateWritesTimeseriesWithKneeForceColumn) {
  const auto out = dir_ / "bike";
  const CliRun r = rdyn("simulate bicycle --model full --duration 0.2 --dt-out 0.01 --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream f(out / "timeseries.csv");
  std::string header;
  std::getline(f, header);
  EXPECT_EQ(header, "t,q,qdot,qddot,energy,work,F_knee");
  int rows = 0;
  for (std::string line; std::getline(f, line);) ++rows;
  EXPECT_EQ(rows, 21);
  EXPECT_TRUE(fs::exists(out / "run.json"));
}

// A periodic table too coarse for its mechanism is flagged (issue #23: the Jansen leg's 10°
// table missed q̈ by 6 % and a reaction by 60 % with exit 0): its m1's half-grid miss is 0.10
// there, 0.001 at 2°; the fourbar's 10° table (1.4e-4) is not flagged. The run still succeeds.
TEST_F(Cli, ACoarsePeriodicTableIsFlaggedAndAFineOneIsNot) {
  const std::string jansen = std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/jansen-leg.yaml";
  auto run = [&](const std::string& scene, const std::string& grid) {
    const auto out = dir_ / ("r" + grid);
    const CliRun r = rdyn("simulate " + scene + " --model reduced --duration 0.2 --grid-deg " + grid + " --out " +
                          out.string() + " --force");
    EXPECT_EQ(r.status, 0) << r.output;
    std::ifstream f(out / "run.json");
    const std::string json((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
    EXPECT_NE(json.find("\"table_m1_half_grid_miss\""), std::string::npos) << json;
    return r.output;
  };
  EXPECT_NE(run(jansen, "10").find("the 10° table looks too coarse for this mechanism"), std::string::npos);
  EXPECT_EQ(run(jansen, "2").find("looks too coarse"), std::string::npos);
  EXPECT_EQ(run("fourbar", "5").find("looks too coarse"), std::string::npos);
}

// Without --grid-deg a periodic table that does not resolve m1 is extracted again at half the
// step (the Jansen leg: 10° → 5° → 2.5°; its 10° run's q̈ was 6 % off with exit 0): the default
// run's q̈ then agrees with a run on a 1.25° grid to 1e-3 of its peak, where
// the 10° run's does not; the fourbar, resolved at 10°, keeps it.
TEST_F(Cli, AnUnresolvedDefaultGridIsRefined) {
  const std::string jansen = std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/jansen-leg.yaml";
  auto qddot = [&](const std::string& args, const std::string& name, std::string* output = nullptr) {
    return simulated(args + " --model reduced --duration 0.5 --dt-out 0.01", name, "qddot", output);
  };
  std::string said;
  const auto auto_grid = qddot(jansen, "auto", &said);
  EXPECT_NE(said.find("the 10° table does not resolve this mechanism"), std::string::npos) << said;
  EXPECT_NE(said.find("extracting at 2.5°"), std::string::npos) << said;
  const auto fine = qddot(jansen + " --grid-deg 1.25", "fine");
  const auto coarse = qddot(jansen + " --grid-deg 10", "coarse");
  ASSERT_EQ(auto_grid.size(), fine.size());
  ASSERT_EQ(coarse.size(), fine.size());
  EXPECT_LT(max_rel_difference(fine, auto_grid), 1e-3);
  EXPECT_GT(max_rel_difference(fine, coarse), 1e-2);
  std::ifstream j(dir_ / "auto" / "run.json");
  const std::string json((std::istreambuf_iterator<char>(j)), std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("\"grid_refined_from_deg\": 10"), std::string::npos) << json;
  qddot("fourbar", "fourbar", &said);
  EXPECT_EQ(said.find("does not resolve"), std::string::npos) << said;
}

// The bicycle with a 0.001 kg·m² flywheel creeps to rest short of the top (q = 11.6°) and falls
// back when a difference far below any model's accuracy has grown: the full model at 0.69 s, the
// reduced one at 0.93 s, after agreeing to 1.3e-8 rad. Both runs say so; the shipped bicycle,
// which turns, does not.
TEST_F(Cli, ARestAtAnUnstableEquilibriumIsToldWhereTheModelsMayPart) {
  CliRun r = rdyn("simulate bicycle --set bicycle_leg.flywheel.inertia_kgm2=0.001 --model reduced --duration 2 --out " +
                  (dir_ / "creep").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("warning: the motion crept to rest near q = 11.6"), std::string::npos) << r.output;
  std::ifstream j(dir_ / "creep" / "run.json");
  const auto run = nlohmann::json::parse(j);
  EXPECT_NEAR(run["unstable_rest"]["q"].get<double>() * 180 / M_PI, 11.61, 0.01);
  EXPECT_GT(run["unstable_rest"]["t_to_s"].get<double>(), run["unstable_rest"]["t_from_s"].get<double>() + 0.3);
  r = rdyn("simulate bicycle --model reduced --duration 2 --out " + (dir_ / "turns").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("crept to rest"), std::string::npos) << r.output;
}

// A default grid whose run misses its own energy balance is refined too (m1's miss does not see
// every table too coarse for its motion): the high-saddle bicycle's 2.5° table resolves m1 but its
// 5 s run loses 3.7 % of the energy scale (exit 1 before); refined, it balances. With its knee
// force requested the knee line (99 % missed through the almost straight leg) refines it first.
// A given grid's failure stands.
TEST_F(Cli, ADefaultGridWhoseRunMissesItsEnergyBalanceIsRefined) {
  const std::string saddle = std::string(RDYN_SCENES) + "/hard/high-saddle.yaml";
  CliRun r = rdyn("simulate " + saddle + " --model reduced --set 'outputs.constraint_forces=[]' "
                  "--set 'validation.thresholds=[]' --out " + (dir_ / "auto").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("the reduced run on the 2.5° table misses its energy balance: extracting at 1.25°"),
            std::string::npos) << r.output;
  std::ifstream j(dir_ / "auto" / "run.json");
  const auto run = nlohmann::json::parse(j);
  EXPECT_LE(run["grid_deg"].get<double>(), 1.25);
  EXPECT_LT(run["energy_balance_residual_J"].get<double>(), 0.01 * run["energy_scale_J"].get<double>());
  r = rdyn("simulate " + saddle + " --model reduced --out " + (dir_ / "knee").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("the 2.5° table does not resolve this mechanism (the force of line knee"),
            std::string::npos) << r.output;
  std::ifstream k(dir_ / "knee" / "run.json");
  const auto knee = nlohmann::json::parse(k);
  EXPECT_LT(knee["energy_balance_residual_J"].get<double>(), 0.01 * knee["energy_scale_J"].get<double>());
  // A step the user gave is theirs to blame: no table is re-extracted for it.
  r = rdyn("simulate bicycle --model reduced --reduced-integrator rk4-fixed --fixed-step 0.5 --duration 3 --out " +
           (dir_ / "coarse").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("energy balance does not close"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("extracting at"), std::string::npos) << r.output;
  r = rdyn("simulate " + saddle + " --model reduced --grid-deg 2.5 --out " + (dir_ / "given").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("energy balance does not close"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "given"));
}

// A default grid is checked by its run: against the run on half the grid, and refined while some
// column changes more than 5e-4 of its peak. The bicycle's 10° table resolves m1 (miss 8e-5), yet
// its knee force is 1.7e-3 off the full model near the straight leg; the check takes 5° (which
// changes 1.7e-6 on 2.5°), within 1e-4 of the full model. A given grid is not checked.
TEST_F(Cli, ADefaultGridIsCheckedAgainstTheRunOnHalfIt) {
  auto knee = [&](const std::string& args, const std::string& name, std::string* said = nullptr) {
    return simulated("bicycle " + args + " --duration 1.5 --dt-out 0.005", name, "F_knee", said);
  };
  std::string said;
  const auto full = knee("--model full", "full");
  const auto checked = knee("--model reduced", "checked", &said);
  const auto given = knee("--model reduced --grid-deg 10", "given");
  EXPECT_NE(said.find("the reduced run on the 10° table changes F_knee by 0.17 % of its peak on half the grid: "
                      "taking the 5° table"),
            std::string::npos) << said;
  ASSERT_EQ(checked.size(), full.size());
  ASSERT_EQ(given.size(), full.size());
  EXPECT_LT(max_rel_difference(full, checked), 1e-4);
  EXPECT_GT(max_rel_difference(full, given), 1e-3);
  std::ifstream j(dir_ / "checked" / "run.json");
  const auto run = nlohmann::json::parse(j);
  EXPECT_EQ(run["grid_deg"].get<double>(), 5);
  EXPECT_EQ(run["grid_refined_from_deg"].get<double>(), 10);
  EXPECT_TRUE(run["grid_check"]["verified"].get<bool>());
  EXPECT_EQ(run["grid_check"]["finer_grid_deg"].get<double>(), 2.5);
  EXPECT_LT(run["grid_check"]["change"].get<double>(), 5e-4);
  std::ifstream g(dir_ / "given" / "run.json");
  EXPECT_FALSE(nlohmann::json::parse(g).contains("grid_check"));
}

// A gate open over ~8° of the crank a turn (5–20 ms; a five-bar geared 3:1, its tool torque on
// while the link l1 turns the positive way) was stepped over by the reduced integrator: exit 0,
// q̈ 22 % and the forces up to 60 % off. Every column now agrees with the full model's within
// 1e-3 of its peak (measured 3.6e-5); a stall against a gate on the crank's own rate stops at once
// (it ran 8 minutes to its step budget), as the full model does.
TEST_F(Cli, AGateWindowShorterThanAStepIsNotSteppedOver) {
  const std::string scenes = std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/";
  for (const char* model : {"full", "reduced"}) {
    const CliRun r = rdyn("simulate " + scenes + "fivebar3-gate-window.yaml --duration 1.5 --model " + model +
                          " --out " + (dir_ / model).string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  auto full = read_columns(dir_ / "full" / "timeseries.csv"), red = read_columns(dir_ / "reduced" / "timeseries.csv");
  ASSERT_EQ(full.size(), red.size());
  double largest_reaction = 0;
  for (const auto& [name, v] : full)
    if (name.rfind("R_", 0) == 0)
      for (double x : v) largest_reaction = std::max(largest_reaction, std::abs(x));
  for (const auto& [name, v] : full) {
    if (name == "t" || name == "q" || name == "energy" || name == "work") continue;
    ASSERT_EQ(red[name].size(), v.size()) << name;
    double peak = name.rfind("R_", 0) == 0 ? 1e-9 * largest_reaction : 0, diff = 0;
    for (size_t i = 0; i < v.size(); ++i) {
      peak = std::max(peak, std::abs(v[i]));
      diff = std::max(diff, std::abs(red[name][i] - v[i]));
    }
    EXPECT_LT(diff, 1e-3 * peak) << name;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const CliRun r = rdyn("simulate " + scenes + "jansen2-backstop.yaml --model reduced --duration 20 --out " +
                        (dir_ / "stall").string());
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("reduced integration stopped at t = 2.15"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("a load switching back and forth at a standstill"), std::string::npos) << r.output;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 60.0);
  EXPECT_FALSE(fs::exists(dir_ / "stall"));
}

TEST_F(Cli, ExtractedTableSimulatesWithoutRebuildingTheFullModel) {
  // extract → CSV → simulate --table gives the same motion as extracting in-process.
  const auto table = dir_ / "bicycle.csv";
  CliRun r = rdyn("extract bicycle --grid-deg 10 --method kinetostatic --out " + table.string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream t(table);
  std::string meta, header;
  std::getline(t, meta);
  while (header.empty() || header[0] == '#') std::getline(t, header);
  EXPECT_EQ(header.rfind("q_deg,m1,m2,me1_knee,me2_knee,", 0), 0u) << header;
  r = rdyn("simulate bicycle --model reduced --table " + table.string() + " --duration 1 --dt-out 0.1 --out " +
           (dir_ / "a").string());
  ASSERT_EQ(r.status, 0) << r.output;
  // The same grid in process (a default grid is checked against half of it, and the bicycle's 10° is
  // refined there: ADefaultGridIsCheckedAgainstTheRunOnHalfIt).
  r = rdyn("simulate bicycle --model reduced --grid-deg 10 --duration 1 --dt-out 0.1 --out " + (dir_ / "b").string());
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream a(dir_ / "a" / "timeseries.csv"), b(dir_ / "b" / "timeseries.csv");
  const std::string ta((std::istreambuf_iterator<char>(a)), {}), tb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_EQ(ta, tb);
}

TEST_F(Cli, BadTableIsRefused) {
  const std::string f = write("table.csv", "# rdyn reduced table: scene=x method=k periodic=1 q0=0 step=1\nq_deg,m1\n0,zz\n");
  expect_refused("simulate bicycle --model reduced --table " + f, "table.csv");
  expect_refused("simulate bicycle --model reduced --grid-deg 7", "7");
}

TEST_F(Cli, MissingSceneFile) { expect_refused("simulate /no/such/scene.yaml", "/no/such/scene.yaml"); }

TEST_F(Cli, EmptyGarbageAndMalformedFiles) {
  expect_refused("simulate " + write("empty.yaml", ""), "empty.yaml");
  expect_refused("simulate " + write("garbage.yaml", std::string("\x7f" "ELF\0\x01\x02\xff\xfe", 9)), "garbage.yaml");
  expect_refused("simulate " + write("bad.yaml", "name: x\nbodies: [\n"), "bad.yaml");
}

TEST_F(Cli, UnknownKeyAndBadOverride) {
  const std::string f = write("typo.yaml", "name: x\nbicycle_leg: {hip_torqe_Nm: 50}\n");
  expect_refused("simulate " + f, "typo.yaml");
  const CliRun r = rdyn("simulate " + f + " --out " + (dir_ / "o").string());
  EXPECT_NE(r.output.find("did you mean 'hip_torque_Nm'"), std::string::npos) << r.output;
  expect_refused("simulate bicycle --set bicycle_leg.subject.mass_kg=-3", "bicycle.yaml");
  expect_refused("simulate bicycle --set loads.nosuch.value=1", "bicycle.yaml");
}

TEST_F(Cli, ImpossibleGeometryNamesTheLoop) {
  // Four-bar whose rocker (0.02 m) cannot reach the coupler: the loop cannot close.
  const std::string f = write("short.yaml", R"(name: short
ground_points: {A: [0, 0], D: [0.3, 0]}
bodies:
  - {name: crank, mass_kg: 0.5, inertia_kgm2: 4.0e-4, points: {B: [0.1, 0]}}
  - {name: coupler, mass_kg: 1.2, inertia_kgm2: 9.0e-3, points: {C: [0.3, 0]}}
  - {name: rocker, mass_kg: 0.7, inertia_kgm2: 6.0e-4, points: {C: [0.02, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank}
  - {name: coupler, type: revolute, parent: crank, parent_point: B, child: coupler}
  - {name: rocker, type: revolute, parent: ground, parent_point: D, child: rocker}
loops:
  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}
independent: crank
)");
  const CliRun r = rdyn("simulate " + f + " --out " + (dir_ / "out").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("short.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("loop 'C' cannot close"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

TEST_F(Cli, UnwritableOutputFolder) {
  const std::string file = write("plainfile", "x");
  const CliRun r = rdyn("simulate bicycle --duration 0.1 --out " + file + "/sub");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
}

}  // namespace

namespace {

// A crank-rocker four-bar whose independent coordinate is the rocker: the rocker swings
// between two dead points, so a reduced table over a full turn cannot exist.
const char* kRockerDriven = R"(name: rocker-driven
ground_points: {A: [0.0, 0.0], D: [0.30, 0.0]}
bodies:
  - {name: crank,   mass_kg: 0.50, com_m: [0.04, 0], inertia_kgm2: 2.667e-4, points: {B: [0.08, 0]}}
  - {name: coupler, mass_kg: 1.20, com_m: [0.14, 0], inertia_kgm2: 7.84e-3,  points: {C: [0.28, 0]}}
  - {name: rocker,  mass_kg: 0.90, com_m: [0.10, 0], inertia_kgm2: 3.0e-3,   points: {C: [0.20, 0]}}
joints:
  - {name: crank,   type: revolute, parent: ground, parent_point: A, child: crank,   guess_deg: 30}
  - {name: coupler, type: revolute, parent: crank,  parent_point: B, child: coupler, guess_deg: 4.85}
  - {name: rocker,  type: revolute, parent: ground, parent_point: D, child: rocker,  guess_deg: 90.27}
loops:
  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}
independent: rocker
initial: {q_deg: 90.27, qdot: 0.0}
)";

TEST_F(Cli, DeadPointInsideTheRangeIsRefused) {
  const std::string f = write("rocker.yaml", kRockerDriven);
  const auto out = dir_ / "t.csv";
  CliRun r = rdyn("extract " + f + " --out " + out.string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("rocker.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("dead point"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
  expect_refused("simulate " + f + " --model reduced", "rocker.yaml");
}

TEST_F(Cli, ValuesAndTopologyErrorsNameTheField) {
  const std::string base = kRockerDriven;
  auto variant = [&](const std::string& from, const std::string& to) {
    std::string t = base;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  struct Case {
    std::string name, text, expect;
  };
  const std::vector<Case> cases = {
      {"nan_mass.yaml", variant("mass_kg: 0.90", "mass_kg: .nan"), "mass_kg"},
      {"neg_mass.yaml", variant("mass_kg: 0.90", "mass_kg: -1"), "mass_kg"},
      {"zero_inertia.yaml", variant("inertia_kgm2: 3.0e-3", "inertia_kgm2: 0"), "inertia"},
      {"two_dof.yaml", variant("loops:\n  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}\n", ""),
       "3 degrees of freedom"},
      {"missing.yaml", variant("independent: rocker\n", ""), "independent"},
      {"truncated.yaml", base.substr(0, base.find("joints:") + 40), "truncated.yaml"},
  };
  for (const auto& c : cases) {
    const std::string f = write(c.name, c.text);
    const CliRun r = rdyn("simulate " + f + " --out " + (dir_ / "o").string());
    EXPECT_EQ(r.status, 2) << c.name << ": " << r.output;
    EXPECT_NE(r.output.find(c.name), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.name << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "o"));
  }
}

TEST_F(Cli, EveryCommandRefusesBadInputWithoutOutput) {
  const std::string bad = write("bad.yaml", "name: x\nbodies: [\n");
  for (const std::string& cmd : std::vector<std::string>{"extract " + bad + " --out " + (dir_ / "t.csv").string(),
                                "validate " + bad + " --out " + (dir_ / "v").string(),
                                "calibrate " + bad + " --write-scene " + (dir_ / "c.yaml").string(),
                                "sweep " + bad + " --vary a=1:2:2 --out " + (dir_ / "s.csv").string()}) {
    const CliRun r = rdyn(cmd);
    EXPECT_EQ(r.status, 2) << cmd << ": " << r.output;
    EXPECT_NE(r.output.find("bad.yaml"), std::string::npos) << r.output;
  }
  for (const char* f : {"t.csv", "v", "c.yaml", "s.csv"}) EXPECT_FALSE(fs::exists(dir_ / f)) << f;
}

}  // namespace

// calibrate --load: JSON names the load, its kind, unit and value; refusals are exit 2 naming
// the field (an unknown load, a motor asked to run beyond its no-load speed).
TEST_F(Cli, CalibrateNamedLoad) {
  const std::string scene = write("fw.yaml",
                                  "name: flywheel\n"
                                  "bodies: [{name: wheel, mass_kg: 2.0, inertia_kgm2: 0.05}]\n"
                                  "joints: [{name: wheel, type: revolute, parent: ground, parent_point: [0, 0], "
                                  "child: wheel}]\n"
                                  "independent: wheel\n"
                                  "loads:\n"
                                  "  - {type: resistance, name: drag, body: wheel, law: viscous, coefficient: 0.02}\n"
                                  "  - {type: motor, name: motor, joint: wheel, stall_torque_Nm: 1.0, "
                                  "no_load_speed_rad_s: 30}\n"
                                  "initial: {q_deg: 0, qdot: 5.0}\n");
  CliRun r = rdyn("calibrate " + scene + " --load motor --cadence-hz 2 2>/dev/null");
  ASSERT_EQ(r.status, 0) << r.output;
  // s = c·ω/(1 − ω/ω0) at ω = 4π rad/s: 0.4324872...
  EXPECT_NE(r.output.find("\"load\": \"motor\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"load_kind\": \"motor_stall_torque\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"load_unit\": \"N·m\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"load_value\": 0.43248724"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("drive_torque_Nm"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"target_power_w\": null"), std::string::npos) << r.output;
  // The confirming run: 7 reduced periods (2 % more), 7 whole revolutions, steady at once.
  EXPECT_NE(r.output.find("\"full_revolutions\": 7,"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"full_duration_s\": 3.5"), std::string::npos) << r.output;  // 3.57 s
  r = rdyn("calibrate " + scene + " --load nope");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("field '--load': no joint_torque, point_force or motor named 'nope'"), std::string::npos) << r.output;
  r = rdyn("calibrate " + scene + " --load motor --cadence-hz 5");
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("field '--load': motor 'motor' cannot hold 5 Hz"), std::string::npos) << r.output;
  r = rdyn("calibrate " + scene);  // no joint torque to scale and no load named
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_NE(r.output.find("field 'validation.calibrate.load'"), std::string::npos) << r.output;
}
