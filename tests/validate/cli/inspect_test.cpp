// `rdyn inspect` end to end: the JSON on standard output and the exit statuses of the contract
// (0 success, 2 bad input naming the file and field, never an abort).
#include "validate/cli/inspect.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "models/scene_yaml.hpp"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status;
  std::string out, err;
};

CliRun rdyn(const std::string& args) {
  const auto err_file = fs::temp_directory_path() / ("rdyn_inspect_err_" + std::to_string(::getpid()));
  const std::string cmd = std::string(RDYN_BINARY) + " " + args + " 2>" + err_file.string();
  CliRun r{-1, "", ""};
  FILE* p = popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) r.out.append(buf.data(), n);
  const int st = pclose(p);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream in(err_file);
  r.err.assign(std::istreambuf_iterator<char>(in), {});
  fs::remove(err_file);
  return r;
}

TEST(InspectCli, FourbarPrintsTheAssembledConfiguration) {
  const CliRun r = rdyn("inspect fourbar");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["degrees_of_freedom"]["value"], 1);
  EXPECT_EQ(j["degrees_of_freedom"]["constraint_rows"], 2);
  EXPECT_NEAR(j["joints"]["crank"]["q_deg"].get<double>(), 30.0, 1e-9);  // the scene's initial q
  // The scene's own guesses (4.85°, 90.27°) are the closed-form assembly to 0.01°.
  EXPECT_NEAR(j["joints"]["coupler"]["q_deg"].get<double>(), 4.85, 0.01);
  EXPECT_NEAR(j["joints"]["rocker"]["q_deg"].get<double>(), 90.27, 0.01);
  EXPECT_LT(j["loops"]["C"]["gap_m"].get<double>(), 1e-10);
  EXPECT_TRUE(j["range"]["full_turn"].get<bool>());
  EXPECT_EQ(j["range"]["reason"].get<std::string>().rfind("full turn: 'crank' turns fully", 0), 0u);
  EXPECT_TRUE(j["warnings"].empty());
}

TEST(InspectCli, RockerDrivenRangeHasTwoDeadPoints) {
  const CliRun r = rdyn("inspect fourbar-rocker");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const auto& range = j["range"];
  EXPECT_FALSE(range["full_turn"].get<bool>());
  ASSERT_EQ(range["dead_points"].size(), 2u);
  // The shared walk's accuracy (~8e-9 rad = 4.3e-7°, measured).
  const double lo = 90.1909862854, hi = 138.5903778907;  // acos((0.36² − 0.13)/0.12), acos((0.20² − 0.13)/0.12)
  EXPECT_NEAR(range["dead_points"][0].get<double>(), lo, 1e-6);
  EXPECT_NEAR(range["dead_points"][1].get<double>(), hi, 1e-6);
  // The domain the models use: 1 % of the dead points' distance inside each, stated in degrees
  // and in words (JSON and standard error).
  EXPECT_EQ(range["dead_point_margin"].get<double>(), 0.01);
  EXPECT_NEAR(range["margin"].get<double>(), 0.01 * (hi - lo), 2e-6);
  EXPECT_NEAR(range["min"].get<double>(), lo + 0.01 * (hi - lo), 2e-6);
  EXPECT_NEAR(range["max"].get<double>(), hi - 0.01 * (hi - lo), 2e-6);
  const std::string why = range["reason"].get<std::string>();
  EXPECT_EQ(why.rfind("dead points found at 90.19098", 0), 0u) << why;
  EXPECT_NE(why.find("and 138.59037"), std::string::npos) << why;
  EXPECT_NE(why.find("0.483994"), std::string::npos) << why;  // 1 % of 48.3994° (the closed forms)
  EXPECT_NE(why.find("(1 % of their distance)"), std::string::npos) << why;
  EXPECT_NE(r.err.find("rdyn: range of 'rocker': " + why), std::string::npos) << r.err;
  EXPECT_EQ(range["min_edge"], "dead_point");
  EXPECT_EQ(range["max_edge"], "dead_point");
  EXPECT_TRUE(range["min_is_dead_point"].get<bool>());
  EXPECT_EQ(range["unit"], "deg");
}

TEST(InspectCli, AnInitialQNextToADeadPointIsExitTwo) {
  // The same refusal simulate and extract give: no output, the dead points named.
  const CliRun r = rdyn("inspect fourbar-rocker --set initial.q_deg=90.5");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("within 1 % of a dead point of 'rocker' (dead points at 90.19"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(InspectCli, FourbarRockerNamesItsBranch) {
  // Guesses of the mirrored assembly (B on the other side of A–C: the coupler's relative angle
  // changes sign) are refused by the branch the scene names, not assembled silently.
  const CliRun r = rdyn("inspect fourbar-rocker --set joints.crank.guess_deg=-26 --set joints.coupler.guess_deg=80");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("joint 'coupler' is at 79.56"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
}

TEST(InspectCli, DeclaredAndUnboundedRanges) {
  const auto dir = fs::temp_directory_path() / ("rdyn_inspect_scenes_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string slider =
      "name: free\nground_points: {O: [0, 0]}\nbodies:\n"
      "  - {name: slider, mass_kg: 1.0, inertia_kgm2: 1.0e-3, points: {P: [0.2, 0]}}\njoints:\n"
      "  - {name: slide, type: prismatic, parent: ground, parent_point: O, child: slider, axis: [1, 0]}\n"
      "independent: slide\ninitial: {q: 0.1}\n";
  std::ofstream(dir / "free.yaml") << slider;
  std::ofstream(dir / "declared.yaml") << slider << "independent_range: [-0.5, 0.75]\n";
  // No dead point: exit 0 (the full model can run it), no finite edges, the reason as a warning.
  CliRun r = rdyn("inspect " + (dir / "free.yaml").string());
  ASSERT_EQ(r.status, 0) << r.err;
  auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["range"].contains("min"));
  EXPECT_NE(j["range"]["unbounded_reason"].get<std::string>().find("meets no dead point"), std::string::npos);
  EXPECT_NE(r.err.find("warning: ") , std::string::npos) << r.err;
  EXPECT_NE(r.err.find("declare independent_range"), std::string::npos) << r.err;
  r = rdyn("inspect " + (dir / "declared.yaml").string());
  ASSERT_EQ(r.status, 0) << r.err;
  j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["range"]["min"].get<double>(), -0.5);
  EXPECT_EQ(j["range"]["max"].get<double>(), 0.75);
  EXPECT_EQ(j["range"]["min_edge"], "declared_limit");
  EXPECT_FALSE(j["range"]["max_is_dead_point"].get<bool>());
  EXPECT_TRUE(j["range"]["dead_points"].empty());
  EXPECT_EQ(j["range"]["reason"], "declared by the scene: independent_range [-0.5, 0.75] m");
  EXPECT_NE(r.err.find("rdyn: range of 'slide': declared by the scene"), std::string::npos) << r.err;
  EXPECT_TRUE(j["warnings"].empty());
  fs::remove_all(dir);
}

TEST(InspectCli, AFlatParallelogramChainIsSingularNotADeadPoint) {
  // It turns fully; twice a turn its loops' Jacobian loses rank (flat at 180° and 360° from the
  // 90° start): passable configurations, listed apart from the dead points.
  CliRun r = rdyn(std::string("inspect ") + RDYN_SCENES + "/chains/chain-3.yaml");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["range"]["full_turn"].get<bool>());
  EXPECT_TRUE(j["range"]["dead_points"].empty());
  ASSERT_EQ(j["range"]["singular_configurations"].size(), 2u);
  EXPECT_NEAR(j["range"]["singular_configurations"][0].get<double>(), 180.0, 1e-6);
  EXPECT_NEAR(j["range"]["singular_configurations"][1].get<double>(), 360.0, 1e-6);
  r = rdyn("inspect fourbar");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(nlohmann::json::parse(r.out)["range"]["singular_configurations"].empty());
}

TEST(InspectCli, BadInputIsExitTwoNamingTheField) {
  CliRun r = rdyn("inspect fourbar --set bodies.crank.mass_kg=-1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("mass_kg"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());
  // A loop that cannot close: the rocker too short to reach the coupler.
  r = rdyn("inspect fourbar --set bodies.rocker.points.C.0=0.01");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("loop 'C' cannot close"), std::string::npos) << r.err;
  // The loop's line and field (the message gave the file alone).
  EXPECT_NE(r.err.find("fourbar.yaml:" + std::to_string(rdyn::models::load_scene("fourbar").line_of("loops.C")) +
                       ": field 'loops.C'"),
            std::string::npos)
      << r.err;
  EXPECT_GT(rdyn::models::load_scene("fourbar").line_of("loops.C"), 0);
  EXPECT_TRUE(r.out.empty());
  r = rdyn("inspect no-such-scene");
  EXPECT_EQ(r.status, 2) << r.err;
}

TEST(InspectCli, FarGuessesWarnOnStandardError) {
  const CliRun r = rdyn("inspect fourbar --set joints.coupler.guess_deg=60");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: joint 'coupler' assembled at"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["warnings"].size(), 1u);
}


TEST(InspectCli, SimulateRecordsTheAssemblyInRunJson) {
  const auto out = fs::temp_directory_path() / ("rdyn_inspect_run_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const CliRun r = rdyn("simulate fourbar --duration 0.01 --out " + out.string() +
                        " --set joints.coupler.guess_deg=60");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: joint 'coupler' assembled at"), std::string::npos) << r.err;
  std::ifstream in(out / "run.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_NEAR(j["assembly"]["crank"]["q_deg"].get<double>(), 30.0, 1e-9);
  EXPECT_NEAR(j["assembly"]["rocker"]["q_deg"].get<double>(), 90.27, 0.01);
  EXPECT_NEAR(j["assembly"]["coupler"]["q_deg"].get<double>(), 4.85, 0.01);
  fs::remove_all(out);
}

TEST(InspectCli, NamedBranchRefusesGuessesOfTheOtherOne) {
  const CliRun r = rdyn(
      "simulate fourbar --duration 0.01 --out /tmp/never-written-rdyn --set loops.C.branch.joint=rocker --set "
      "loops.C.branch.sign=positive --set joints.rocker.guess_deg=-110 --set joints.coupler.guess_deg=-84.5");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("loop 'C' assembled on the other branch"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists("/tmp/never-written-rdyn"));
}

}  // namespace
