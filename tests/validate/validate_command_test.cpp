// `rdyn validate` end to end on a small suite: outputs, thresholds and exit status.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

int run(const std::string& args, std::string& out) {
  FILE* p = popen((std::string(RDYN_BINARY) + " " + args + " 2>&1").c_str(), "r");
  std::array<char, 4096> buf{};
  while (size_t n = fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

TEST(ValidateCommand, SuiteWritesReportsAndFailsOnAThreshold) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_suite_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "suite");
  // The four-bar with a loose threshold (passes) and an impossible one (fails), plus a broken scene.
  const std::string fourbar = std::string(RDYN_SCENES) + "/fourbar.yaml";
  std::ifstream in(fourbar);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(dir / "suite" / "a_pass.yaml") << text << "validation: {duration_s: 2, thresholds: [{quantity: qdot, grid_deg: 10, max_error: 0.05}]}\n";
  std::ofstream(dir / "suite" / "b_fail.yaml") << text << "validation: {duration_s: 2, thresholds: [{quantity: rocker_axial, grid_deg: 30, max_error: 1.0e-12}]}\n";
  std::ofstream(dir / "suite" / "c_broken.yaml") << "name: broken\nbodies: 3\n";
  std::string out;
  const int status = run("validate --suite " + (dir / "suite").string() + " --out " + (dir / "out").string(), out);
  EXPECT_EQ(status, 1) << out;
  std::ifstream sf(dir / "out" / "summary.json");
  const auto j = nlohmann::json::parse(sf);
  ASSERT_EQ(j["scenes"].size(), 3u);
  EXPECT_EQ(j["scenes"][0]["status"], "pass");
  EXPECT_EQ(j["scenes"][1]["status"], "fail");
  EXPECT_EQ(j["scenes"][2]["status"], "error");
  EXPECT_TRUE(fs::exists(dir / "out" / "index.html"));
  for (const char* f : {"report.html", "summary.json", "params.svg", "timeseries.svg", "pareto.svg", "convergence.svg",
                        "params.gp", "compare.csv", "runs.csv"})
    EXPECT_TRUE(fs::exists(dir / "out" / "a_pass" / f)) << f;
  std::ifstream rep(dir / "out" / "a_pass" / "report.html");
  const std::string html((std::istreambuf_iterator<char>(rep)), {});
  EXPECT_EQ(html.find("could not be rendered"), std::string::npos);
  EXPECT_GE(std::count(html.begin(), html.end(), '\n'), 1);
  size_t svgs = 0;
  for (size_t at = html.find("<svg"); at != std::string::npos; at = html.find("<svg", at + 1)) ++svgs;
  EXPECT_GE(svgs, 4u);
  fs::remove_all(dir);
}

}  // namespace
