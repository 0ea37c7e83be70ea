// "Never silently wrong" for the full model end to end (issue #22 items 2, 5, 6): a run that
// switches assembly branch is exit 1 naming the time and the joint; a start at a singular
// configuration is exit 2 naming `initial` and its line in simulate and inspect; a spring whose
// ends coincide at assembly is exit 2 naming its field and line. Nothing is written.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

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

TEST_F(BranchCli, ABranchSwitchIsExitOneNamingTheTimeAndTheJoint) {
  // Merson at 1e-6 leaves the parallelogram branch at the aligned position it meets at 1.16 s.
  const auto r = test::run_rdyn(
      {"simulate", kParallelogram, "--model", "full", "--integrator", "rkmerson", "--tolerance", "1e-6", "--out", "o"},
      dir);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("full model switched assembly branch between t = 1.158 s and t = 1.16 s: joint 'rocker' is at "
                       "1797.4"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "o"));
  // The scene's reference setting (CPodes at 1e-7) stays on its branch.
  const auto ok = test::run_rdyn(
      {"simulate", kParallelogram, "--model", "full", "--integrator", "cpodes", "--tolerance", "1e-7", "--out", "c"},
      dir);
  EXPECT_EQ(ok.status, 0) << ok.err;
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
