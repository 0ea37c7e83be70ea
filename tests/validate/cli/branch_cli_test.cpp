// "Never silently wrong" for the full model end to end: through a parallelogram's aligned
// positions the full model keeps its branch and energy (singular passages); a start at a singular
// configuration is exit 2 naming `initial` and its line in simulate and inspect; a spring whose
// ends coincide at assembly is exit 2 naming its field and line. Nothing is written.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) out.push_back(f);
  return out;
}

struct BranchCli : ::testing::Test {
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() / ("rdyn_branch_" + std::to_string(::getpid()) + "_" +
                                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
};

const std::string kParallelogram = RDYN_SCENES "/hard/parallelogram.yaml";

TEST_F(BranchCli, ThroughItsAlignedPositionsTheFullModelKeepsItsBranchAndEnergy) {
  // Merson at 1e-6 left the parallelogram branch at the aligned position it meets at 1.16 s (the
  // branch guard made that exit 1; engine/forward_dynamics_test.cpp keeps that case). The singular
  // passages cross each aligned position in the independent coordinate: exit 0 and, the scene
  // being conservative, an energy column constant to 1 % of itself (measured at this loose
  // tolerance: 4.6e-4 at most) — the other branch lost 5.9 of its 5.9 J.
  for (const char* integrator : {"rkmerson", "cpodes"}) {
    const auto r = test::run_rdyn({"simulate", kParallelogram, "--model", "full", "--integrator", integrator,
                                   "--tolerance", "1e-6", "--out", integrator},
                                  dir);
    ASSERT_EQ(r.status, 0) << integrator << ": " << r.err;
    std::ifstream in(dir / integrator / "timeseries.csv");
    std::string line;
    std::getline(in, line);
    const auto header = split(line);
    const size_t e = std::find(header.begin(), header.end(), "energy") - header.begin();
    ASSERT_LT(e, header.size()) << line;
    double e0 = NAN, drift = 0.0, q_end = 0.0;
    while (std::getline(in, line)) {
      const auto v = split(line);
      const double energy = std::stod(v.at(e));
      if (std::isnan(e0)) e0 = energy;
      drift = std::max(drift, std::abs(energy - e0));
      q_end = std::stod(v.at(1));
    }
    EXPECT_LT(drift, 1e-2 * std::abs(e0)) << integrator;
    EXPECT_GT(q_end, 4 * 3.14159265358979323846) << integrator;  // two turns, four aligned positions
  }
}

TEST_F(BranchCli, ASingularStartIsExitTwoNamingInitialInSimulateAndInspect) {
  // Aligned at 0°: the loop Jacobian loses rank (locally 2 degrees of freedom); the full model
  // ran from here with forces of ~1e6 N before, while extraction refused it.
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"simulate", kParallelogram, "--model", "full", "--set", "initial.q_deg=0", "--out",
                                 "o"},
        std::vector<std::string>{"simulate", kParallelogram, "--model", "reduced", "--set", "initial.q_deg=0", "--out",
                                 "o"},
        std::vector<std::string>{"inspect", kParallelogram, "--set", "initial.q_deg=0"}}) {
    const auto r = test::run_rdyn(args, dir);
    EXPECT_EQ(r.status, 2) << args[0] << " " << args[3] << ": " << r.err;
    EXPECT_NE(r.err.find("parallelogram.yaml:23: field 'initial': the mechanism starts at a singular configuration "
                         "of 'crank'"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("locally 2 degrees of freedom"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(fs::exists(dir / "o"));
  }
}

TEST_F(BranchCli, ASpringWithCoincidentEndsIsExitTwoNamingItsField) {
  // A crank whose spring runs from ground (0.1, 0) to the crank's tip, which sits there at 0°.
  std::ofstream(dir / "spring.yaml") << R"(name: sprung_crank
ground_points: {O: [0, 0]}
bodies:
  - {name: crank, mass_kg: 1.0, com_m: [0.05, 0], inertia_kgm2: 2.0e-3, points: {B: [0.1, 0]}}
joints:
  - {name: crank, type: revolute, parent: ground, parent_point: O, child: crank}
independent: crank
loads:
  - {type: spring, name: k, body_a: ground, point_a: [0.1, 0], body_b: crank, point_b: B, stiffness_N_per_m: 100,
     rest_length_m: 0.05}
gravity: {enabled: false}
initial: {q_deg: 0, qdot: 2.0}
simulation: {duration_s: 2, output_interval_s: 0.01}
)";
  for (const char* model : {"full", "reduced"}) {
    const auto r = test::run_rdyn({"simulate", "spring.yaml", "--model", model, "--out", "o"}, dir);
    EXPECT_EQ(r.status, 2) << model << ": " << r.err;
    EXPECT_NE(r.err.find("spring.yaml:9: field 'loads.k.point_b': spring 'k'"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "o"));
  }
}

}  // namespace
}  // namespace rdyn::validate

namespace rdyn::validate {
namespace {

// A row that lands within ~1e-4 rad of a chain's flat configuration, where the constraint forces
// are not determined, is the limit stencil's interpolation: the run says so (a warning and
// run.json's rows_interpolated_at_rank_loss), and a run whose rows stay clear of it does not.
TEST(BranchCliRows, RowsInterpolatedAtRankLossAreCountedAndSaid) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("rdyn_interp_rows_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string chain = std::string(RDYN_SCENES) + "/chains/chain-1.yaml";
  // From 0.003° toward 0 at 0.01 rad/s: |q| < 3e-5 rad for a few ms around t = 5 ms.
  const auto near = test::run_rdyn({"simulate", chain, "--model", "full", "--set", "initial.q_deg=0.003", "--set",
                                    "initial.qdot=-0.01", "--duration", "0.02", "--dt-out", "0.001", "--out", "near"},
                                   dir);
  ASSERT_EQ(near.status, 0) << near.err;
  EXPECT_NE(near.err.find("lie within ~1e-4 rad of a configuration where the loop Jacobian loses rank"),
            std::string::npos)
      << near.err;
  EXPECT_GE(nlohmann::json::parse(test::slurp(dir / "near/run.json")).at("rows_interpolated_at_rank_loss").get<long>(),
            1);
  const auto clear = test::run_rdyn({"simulate", chain, "--model", "full", "--duration", "0.5", "--out", "clear"}, dir);
  ASSERT_EQ(clear.status, 0) << clear.err;
  EXPECT_EQ(clear.err.find("loses rank"), std::string::npos) << clear.err;
  EXPECT_EQ(nlohmann::json::parse(test::slurp(dir / "clear/run.json")).at("rows_interpolated_at_rank_loss"), 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate
