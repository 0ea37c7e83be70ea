// A command-line value out of its range (validate/io/argument_error.hpp): an ArgumentError is a
// std::runtime_error carrying its text, and rdyn's main maps it to exit status 2 with the option
// named on standard error and no output written.
#include "validate/io/argument_error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <unistd.h>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

TEST(ArgumentError, IsARuntimeErrorCarryingItsText) {
  const std::string text = "--duration: must be a finite number in (0, 100000] s (got 1000000000)";
  try {
    throw ArgumentError(text);
  } catch (const std::runtime_error& e) {  // caught as its base: main's other handlers see it too
    EXPECT_EQ(std::string(e.what()), text);
    EXPECT_NE(dynamic_cast<const ArgumentError*>(&e), nullptr);
  }
}

// Spawns rdyn: simulate checks --duration before any work (cli_limits::kMaxDuration_s = 1e5 s).
TEST(ArgumentError, MainMapsItToExitStatusTwo) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_argument_error_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto r = test::run_rdyn({"simulate", "fourbar", "--duration", "1e9", "--out", "o"}, dir);
  EXPECT_FALSE(r.timed_out);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("rdyn: error: --duration"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(got 1000000000)"), std::string::npos) << r.err;  // the value typed, shown back
  EXPECT_FALSE(fs::exists(dir / "o"));
  for (const auto& e : fs::directory_iterator(dir)) ADD_FAILURE() << "left behind: " << e.path();
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate
