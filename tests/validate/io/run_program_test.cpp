// External programs run without a shell: arguments arrive verbatim, metacharacters do
// nothing, the working folder and log are honoured, and a hang is cut at the limit.
#include "validate/io/run_program.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("rdyn_spawn_" + std::to_string(getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
  std::string read(const std::string& name) const {
    std::ifstream f(path / name);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
};

TEST(RunProgram, ArgumentsAreNotInterpretedByAShell) {
  TempDir d;
  const std::string hostile = "x';touch PWNED;'$(touch PWNED2)`touch PWNED3`";
  const auto r = run_program({"printf", "%s", hostile}, d.path.string(), (d.path / "log").string(), 10.0);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(d.read("log"), hostile);
  for (const char* f : {"PWNED", "PWNED2", "PWNED3"}) EXPECT_FALSE(fs::exists(d.path / f));
}

TEST(RunProgram, RunsInTheWorkingFolderAndReportsTheExitCode) {
  TempDir d;
  std::ofstream(d.path / "here.txt") << "found\n";
  const auto r = run_program({"cat", "here.txt"}, d.path.string(), (d.path / "log").string(), 10.0);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(d.read("log"), "found\n");
  const auto missing = run_program({"cat", "absent.txt"}, d.path.string(), (d.path / "log").string(), 10.0);
  EXPECT_TRUE(missing.started);
  EXPECT_FALSE(missing.ok());
  EXPECT_NE(missing.exit_code, 0);
}

TEST(RunProgram, MissingProgramAndTimeLimit) {
  TempDir d;
  const auto none = run_program({"rdyn-no-such-program"}, d.path.string(), (d.path / "log").string(), 10.0);
  EXPECT_FALSE(none.ok());
  EXPECT_FALSE(none.error.empty());
  const auto slow = run_program({"sleep", "30"}, d.path.string(), (d.path / "log").string(), 0.3);
  EXPECT_TRUE(slow.timed_out);
  EXPECT_FALSE(slow.ok());
}

}  // namespace
}  // namespace rdyn::validate
