// `rdyn expand` end to end: the expanded scene is what every command reads as the original
// (the same extraction table, byte for byte; the same assembled configuration), it is written
// through the safe single-file output, and bad input gives status 2.
#include "validate/cli/expand.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

class ExpandCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rdyn-expand-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  test::RdynRun rdyn(const std::vector<std::string>& args) { return test::run_rdyn(args, dir_); }
  // `rdyn inspect` JSON without the scene file's path (the one thing that differs).
  nlohmann::json inspect(const std::string& scene) {
    const auto r = rdyn({"inspect", scene});
    EXPECT_EQ(r.status, 0) << r.err;
    auto j = nlohmann::json::parse(r.out, nullptr, false);
    if (j.is_object()) j.erase("scene_file");
    return j;
  }
  fs::path dir_;
};

// The bicycle is generated (bicycle_leg): its expansion gives the same table and assembly.
TEST_F(ExpandCli, ExpandedBicycleGivesTheSameTableAndAssembly) {
  auto r = rdyn({"expand", "bicycle", "--out", "bicycle-expanded.yaml"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string yaml = test::slurp(dir_ / "bicycle-expanded.yaml");
  EXPECT_EQ(yaml.rfind("# Written by rdyn from scene 'bicycle' (", 0), 0u) << yaml;
  EXPECT_EQ(yaml.find("bicycle_leg"), std::string::npos);
  ASSERT_EQ(rdyn({"extract", "bicycle", "--out", "original.csv"}).status, 0);
  r = rdyn({"extract", "bicycle-expanded.yaml", "--out", "expanded.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string table = test::slurp(dir_ / "original.csv");
  ASSERT_GT(table.size(), 1000u);
  EXPECT_EQ(test::slurp(dir_ / "expanded.csv"), table);  // header (scene hash) and every number
  const auto a = inspect("bicycle"), b = inspect("bicycle-expanded.yaml");
  ASSERT_TRUE(a.contains("joints")) << a.dump(2);
  EXPECT_EQ(a, b);
  // Expanding the expansion gives the same text (apart from the file named in the header).
  r = rdyn({"expand", "bicycle-expanded.yaml"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.substr(r.out.find('\n')), yaml.substr(yaml.find('\n')));
}

TEST_F(ExpandCli, RangeSceneGivesTheSameTable) {
  ASSERT_EQ(rdyn({"expand", "crane-luffing", "--out", "crane.yaml"}).status, 0);
  ASSERT_EQ(rdyn({"extract", "crane-luffing", "--out", "a.csv"}).status, 0);
  ASSERT_EQ(rdyn({"extract", "crane.yaml", "--out", "b.csv"}).status, 0);
  EXPECT_EQ(test::slurp(dir_ / "b.csv"), test::slurp(dir_ / "a.csv"));
}

TEST_F(ExpandCli, AppliesOverridesAndWritesSafely) {
  auto r = rdyn({"expand", "fourbar", "--set", "loads.bearing.coefficient=0.25"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("name: bearing, body: crank, law: viscous, coefficient: 0.25}"),
            std::string::npos)
      << r.out;
  // A re-run replaces rdyn's own file; a foreign file is kept unless --force.
  ASSERT_EQ(rdyn({"expand", "fourbar", "--out", "f.yaml"}).status, 0);
  EXPECT_EQ(rdyn({"expand", "slider-crank", "--out", "f.yaml"}).status, 0);
  EXPECT_NE(test::slurp(dir_ / "f.yaml").find("name: slider-crank\n"), std::string::npos);
  { std::ofstream(dir_ / "mine.yaml") << "name: mine\n"; }
  r = rdyn({"expand", "fourbar", "--out", "mine.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("mine.yaml"), std::string::npos) << r.err;
  EXPECT_EQ(test::slurp(dir_ / "mine.yaml"), "name: mine\n");
  EXPECT_EQ(rdyn({"expand", "fourbar", "--out", "mine.yaml", "--force"}).status, 0);
  EXPECT_EQ(test::slurp(dir_ / "mine.yaml").rfind("# Written by rdyn from scene 'fourbar'", 0), 0u);
}

TEST_F(ExpandCli, BadInputIsStatus2AndWritesNothing) {
  auto r = rdyn({"expand", "fourbar", "--set", "bodies.crank.mass_kg=-1", "--out", "x.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("mass_kg"), std::string::npos) << r.err;
  r = rdyn({"expand", "no-such-scene", "--out", "x.yaml"});
  EXPECT_EQ(r.status, 2);
  r = rdyn({"expand", "fourbar", "--set", "nonsense", "--out", "x.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(dir_ / "x.yaml"));
}

// Hostile destinations and sources: a full disk, an endless file as the scene, a link to a
// foreign file; each is status 2 and leaves nothing behind.
TEST_F(ExpandCli, HostileDestinationsAndSourcesAreStatus2) {
  auto r = rdyn({"expand", "fourbar", "--out", "/dev/full"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("No space left"), std::string::npos) << r.err;
  r = rdyn({"expand", "/dev/zero", "--out", "z.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("not a regular file (a character device)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "z.yaml"));
  { std::ofstream(dir_ / "foreign.txt") << "keep me\n"; }
  fs::create_symlink("foreign.txt", dir_ / "link.yaml");
  r = rdyn({"expand", "fourbar", "--out", "link.yaml"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(test::slurp(dir_ / "foreign.txt"), "keep me\n");
  for (const auto& e : fs::directory_iterator(dir_))  // no temporary left behind
    EXPECT_EQ(e.path().filename().string().find("tmp"), std::string::npos) << e.path();
}

TEST(ExpandedScene, IsRecognisedByItsFirstLine) {
  EXPECT_TRUE(
      is_rdyn_expanded_scene("# Written by rdyn from scene 'fourbar' (f.yaml).\nname: fourbar\n"));
  EXPECT_FALSE(is_rdyn_expanded_scene("name: fourbar\n# Written by rdyn from scene 'fourbar'\n"));
  EXPECT_FALSE(is_rdyn_expanded_scene(""));
}

}  // namespace
}  // namespace rdyn::validate
