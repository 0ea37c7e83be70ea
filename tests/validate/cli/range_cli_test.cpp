// Range-limited independent coordinates end to end through the rdyn binary (issue #10):
// `extract` writes periodic=0 tables and reports the range, both models stop at the domain edge
// with status 1 and nothing written, and a range scene validates against its thresholds.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

struct RangeCli : ::testing::Test {
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("rdyn_range_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
};

TEST_F(RangeCli, ExtractWritesARangeTableAndReportsTheDeadPoints) {
  const auto r = test::run_rdyn({"extract", "slider-crank-slider", "--out", "t.csv"}, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("range [0.150999999, 0.249000001] m (dead point / dead point), dead points at 0.149999999 m "
                       "and 0.250000001 m"),
            std::string::npos)
      << r.err;
  const std::string t = test::slurp(dir / "t.csv");
  // The stroke between the dead points sampled kDeadPointRefinement × finer: 360 intervals at 10°.
  EXPECT_NE(r.err.find("0.000272222 m grid: 360 intervals from a 10° grid, ten times finer toward dead points, 361 points"), std::string::npos) << r.err;
  EXPECT_NE(t.find("periodic=0"), std::string::npos);
  EXPECT_NE(t.find("edges=dead_point,dead_point"), std::string::npos);
  EXPECT_NE(t.find("\nq_m,m1,"), std::string::npos);
  // The table runs the reduced model as extraction at run time does.
  const auto s = test::run_rdyn(
      {"simulate", "slider-crank-slider", "--model", "reduced", "--table", "t.csv", "--out", "red"}, dir);
  EXPECT_EQ(s.status, 0) << s.err;
  const auto run = nlohmann::json::parse(test::slurp(dir / "red/run.json"));
  EXPECT_EQ(run.at("table"), "t.csv");
}

TEST_F(RangeCli, BothModelsStopAtTheSameEdgeWithStatusOneAndNoOutput) {
  for (const char* model : {"full", "reduced"}) {
    const auto r = test::run_rdyn({"simulate", "slider-crank-slider", "--model", model, "--set", "initial.qdot=3",
                                   "--out", std::string("out_") + model},
                                  dir);
    EXPECT_EQ(r.status, 1) << model << ": " << r.err;
    EXPECT_NE(r.err.find(std::string(model) + " model left the validity domain at q = 0.249000001 m (dead point) at "
                                              "t = 0.00939"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / (std::string("out_") + model))) << model;
  }
  // Inside the range the reduced run records the range it used.
  const auto ok = test::run_rdyn({"simulate", "slider-crank-slider", "--model", "reduced", "--out", "in"}, dir);
  ASSERT_EQ(ok.status, 0) << ok.err;
  const auto run = nlohmann::json::parse(test::slurp(dir / "in/run.json"));
  EXPECT_EQ(run.at("independent_range").at("min_edge"), "dead point");
  EXPECT_NEAR(run.at("dead_points")[1].get<double>(), 0.25, 1e-8);
}

// The isosceles slider-crank's rod force has a pole where it folds (x = 0): extract records it in
// the table, the reduced model refuses the rows near it with status 1 and nothing written (it gave
// 0.23 N for the full model's 28.4 N with status 0), and the full model runs.
TEST_F(RangeCli, AConstraintForcePoleIsRecordedAndTheReducedModelRefusesItsRows) {
  const std::string scene = std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/iso-slider-crank.yaml";
  const auto e = test::run_rdyn({"extract", scene, "--out", "t.csv"}, dir);
  ASSERT_EQ(e.status, 0) << e.err;
  EXPECT_NE(test::slurp(dir / "t.csv").find("\n# pole rod_axial: "), std::string::npos);
  const auto r = test::run_rdyn({"simulate", scene, "--model", "reduced", "--table", "t.csv", "--out", "red"}, dir);
  EXPECT_EQ(r.status, 1) << r.err;
  // The refusal radius is 8 grid steps (reduced_model.cpp); the range ends at dead points, so the
  // table is kDeadPointRefinement× finer (8 × 0.00108889 m) and the run is refused on reaching it,
  // no longer at its start.
  EXPECT_NE(r.err.find("cannot give constraint force 'rod_axial' at t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("within 0.00871111 m of it"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "red"));
  const auto f = test::run_rdyn({"simulate", scene, "--model", "full", "--duration", "0.2", "--out", "full"}, dir);
  EXPECT_EQ(f.status, 0) << f.err;
}

TEST_F(RangeCli, TheCraneValidatesWithinItsThresholdsWithoutCycleWords) {
  test::RunLimits limits;
  limits.time_limit_s = 300;
  const auto r = test::run_rdyn({"validate", "crane-luffing", "--quick", "--out", "v"}, dir, limits);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(test::slurp(dir / "v/summary.json"));
  ASSERT_EQ(s.at("thresholds").size(), 2u);
  for (const auto& t : s.at("thresholds")) EXPECT_TRUE(t.at("pass").get<bool>()) << t.dump();
  const std::string html = test::slurp(dir / "v/report.html");
  EXPECT_EQ(html.find("cycle"), std::string::npos);
  EXPECT_EQ(html.find("revolution"), std::string::npos);
  EXPECT_NE(html.find("moves within a range"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
