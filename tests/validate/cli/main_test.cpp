// rdyn's entry point (validate/cli/main.cpp): help for the program and for every subcommand it
// lists, exit status 2 for a command line that names no subcommand or one that does not exist
// (named in the message), and the status map of the errors a command throws.
#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

class Main : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rdyn_main_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  test::RdynRun rdyn(const std::vector<std::string>& args) { return test::run_rdyn(args, dir_); }
  fs::path dir_;
};

// The subcommands `rdyn --help` lists: the first word of each line under "Subcommands:".
std::vector<std::string> listed_subcommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help);
  bool in_list = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("Subcommands:", 0) == 0 || line.rfind("SUBCOMMANDS:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (!in_list) continue;
    if (line.rfind("  ", 0) != 0) break;
    std::istringstream words(line);
    std::string name;
    words >> name;
    if (!name.empty()) names.push_back(name);
  }
  return names;
}

TEST_F(Main, HelpExplainsItself) {
  const auto r = rdyn({"--help"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("reduced-parameter models"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("A SCENE is a shipped scene name"), std::string::npos) << r.out;
  const auto names = listed_subcommands(r.out);
  // The subcommands docs/cli.md and the README describe, each listed once.
  const std::set<std::string> unique(names.begin(), names.end());
  EXPECT_EQ(unique.size(), names.size());
  for (const char* n : {"simulate", "extract", "calibrate", "validate", "report", "sweep", "inspect", "export-mjcf",
                        "optimize", "drive", "expand", "animate"})
    EXPECT_EQ(unique.count(n), 1u) << n << " not listed in:\n" << r.out;
  EXPECT_EQ(rdyn({"-h"}).status, 0);
}

TEST_F(Main, EveryListedSubcommandAnswersHelp) {
  const auto names = listed_subcommands(rdyn({"--help"}).out);
  ASSERT_GE(names.size(), 12u);
  for (const auto& n : names) {
    const auto r = rdyn({n, "--help"});
    EXPECT_EQ(r.status, 0) << n << ": " << r.err;
    EXPECT_NE(r.out.find("Usage:"), std::string::npos) << n << ": " << r.out;
    EXPECT_NE(r.out.find(n), std::string::npos) << n;
    EXPECT_EQ(r.err, "") << n;
  }
  EXPECT_TRUE(fs::is_empty(dir_)) << "help wrote a file";
}

TEST_F(Main, AnUnknownSubcommandExitsTwoNamingIt) {
  for (const std::string typed : {"simualte", "frobnicate", "validte"}) {
    const auto r = rdyn({typed, "fourbar", "--out", "o"});
    EXPECT_EQ(r.status, 2) << typed;
    EXPECT_NE(r.err.find("unknown subcommand '" + typed + "'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("simulate, extract"), std::string::npos) << r.err;  // the valid ones, in order
    EXPECT_FALSE(fs::exists(dir_ / "o"));
  }
  // A control character is shown, not written to the terminal.
  const auto r = rdyn({std::string("bad\x1b[2Jname")});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("'bad\\x1b[2Jname'"), std::string::npos) << r.err;
}

// The parser's own refusals carry the prefix every refusal has, user text shown, not written.
TEST_F(Main, ParserRefusalsHaveThePrefix) {
  auto r = rdyn({"simulate", "fourbar", "--model", "bogus", "--out", "o"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.rfind("rdyn: error: --model: bogus not in {full,reduced}", 0), 0u) << r.err;
  r = rdyn({"simulate", "fourbar", "--model", std::string("a\x1b[2Jb"), "--out", "o"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("a\\x1b[2Jb"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

TEST_F(Main, NoSubcommandExitsTwo) {
  const auto r = rdyn({});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("A subcommand is required"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  // An option alone is not a subcommand either.
  EXPECT_EQ(rdyn({"--out", "o"}).status, 2);
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

// The map main applies to a command's errors (README, "Exit status"): bad input 2 with
// "rdyn: error:", a numerical failure 1 with "rdyn: numerical failure:".
TEST_F(Main, CommandErrorsMapToTheirExitStatus) {
  const auto missing = rdyn({"inspect", "/no/such/scene.yaml"});  // SceneError
  EXPECT_EQ(missing.status, 2);
  EXPECT_EQ(missing.err.rfind("rdyn: error: ", 0), 0u) << missing.err;
  const auto range = rdyn({"simulate", "fourbar", "--dt-out", "0", "--out", "o"});  // ArgumentError
  EXPECT_EQ(range.status, 2);
  EXPECT_NE(range.err.find("rdyn: error: --dt-out"), std::string::npos) << range.err;
  const auto parse = rdyn({"simulate", "fourbar", "--model", "half", "--out", "o"});  // CLI11's own check
  EXPECT_EQ(parse.status, 2);
  EXPECT_NE(parse.err.find("--model"), std::string::npos) << parse.err;
  EXPECT_FALSE(fs::exists(dir_ / "o"));
}

}  // namespace
}  // namespace rdyn::validate
