// The shared command-line options: a typed value is recorded as typed, an untyped one leaves the
// variable and its flag alone (the scene's validation.calibrate decides), the checks refuse what
// they must, and `rdyn calibrate --help` and `rdyn optimize --help` list them alike.
#include "validate/cli/cli_options.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

struct Parsed {
  double cadence_hz = 1.0, power_w = 0.0, grid_deg = 10.0;
  bool cadence_given = false, power_given = false, force = false;
  std::string interpolation = "fourier", out;
  std::vector<std::string> sets;
};

// A command with every shared option; parse(args) returns the error CLI11 gives ("" when none).
struct Command {
  CLI::App app{"test"};
  Parsed p;
  Command() {
    add_operating_point_options(app, p.cadence_hz, p.cadence_given, p.power_w, p.power_given);
    add_reduced_table_options(app, p.grid_deg, p.interpolation);
    add_scene_overrides(app, p.sets);
    add_output_folder(app, p.out, p.force);
  }
  std::string parse(std::vector<std::string> args) {
    std::reverse(args.begin(), args.end());  // CLI11 takes a vector in reverse order
    try {
      app.parse(args);
    } catch (const CLI::ParseError& e) {
      return e.what();
    }
    return "";
  }
};

TEST(CliOptions, TypedValuesAreRecordedAsTyped) {
  Command c;
  ASSERT_EQ(c.parse({"--cadence-hz", "1.5", "--power-w", "80", "--grid-deg", "5", "--interp", "cubic", "--set",
                     "a.b=1", "--set", "c=2", "--out", "dir", "--force"}),
            "");
  EXPECT_EQ(c.p.cadence_hz, 1.5);
  EXPECT_TRUE(c.p.cadence_given);
  EXPECT_EQ(c.p.power_w, 80.0);
  EXPECT_TRUE(c.p.power_given);
  EXPECT_EQ(c.p.grid_deg, 5.0);
  EXPECT_EQ(c.p.interpolation, "cubic");
  EXPECT_EQ(c.p.sets, (std::vector<std::string>{"a.b=1", "c=2"}));
  EXPECT_EQ(c.p.out, "dir");
  EXPECT_TRUE(c.p.force);
}

TEST(CliOptions, UntypedOperatingPointKeepsDefaultsAndIsNotGiven) {
  Command c;
  ASSERT_EQ(c.parse({"--out", "dir"}), "");
  EXPECT_FALSE(c.p.cadence_given);
  EXPECT_FALSE(c.p.power_given);
  EXPECT_EQ(c.p.cadence_hz, 1.0);
  EXPECT_EQ(c.p.power_w, 0.0);
  EXPECT_FALSE(c.p.force);
  // A typed zero is typed (the command refuses it, naming the option), not "not given".
  Command z;
  ASSERT_EQ(z.parse({"--power-w", "0", "--out", "dir"}), "");
  EXPECT_TRUE(z.p.power_given);
  EXPECT_FALSE(z.p.cadence_given);
}

TEST(CliOptions, ChecksRefuseWhatTheyMust) {
  EXPECT_NE(Command().parse({"--interp", "spline", "--out", "dir"}), "");  // not an interpolant
  EXPECT_NE(Command().parse({"--cadence-hz", "fast", "--out", "dir"}), "");  // not a number
  EXPECT_NE(Command().parse({"--cadence-hz", "1", "--cadence-hz", "2", "--out", "dir"}), "");  // twice
  EXPECT_NE(Command().parse({"--cadence-hz", "1"}), "");  // --out is required
}

// The help line of `option` in `rdyn <command> --help` (with its wrapped continuation lines).
std::string help_entry(const std::string& help, const std::string& option) {
  const auto at = help.find("\n  " + option + " ");
  if (at == std::string::npos) return "";
  auto end = help.find("\n  -", at + 1);
  if (end == std::string::npos) end = help.size();
  std::string e = help.substr(at, end - at);
  while (!e.empty() && (e.back() == '\n' || e.back() == ' ')) e.pop_back();  // the last entry ends the text
  return e;
}

TEST(CliOptions, CalibrateAndOptimizeListTheSharedOptionsAlike) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto cal = test::run_rdyn({"calibrate", "--help"}, dir), opz = test::run_rdyn({"optimize", "--help"}, dir);
  ASSERT_EQ(cal.status, 0);
  ASSERT_EQ(opz.status, 0);
  for (const char* name : {"--cadence-hz", "--power-w", "--set", "--grid-deg", "--interp"}) {
    const std::string e = help_entry(cal.out, name);
    EXPECT_NE(e, "") << name;
    EXPECT_EQ(e, help_entry(opz.out, name)) << name;
  }
  // The option that differs: calibrate's --force replaces a file (--write-scene), optimize's a folder.
  EXPECT_NE(help_entry(cal.out, "--force").find(kForceHelpFile), std::string::npos);
  EXPECT_NE(help_entry(opz.out, "--force").find("Write into an existing folder"), std::string::npos);
  EXPECT_NE(help_entry(opz.out, "--out").find("REQUIRED"), std::string::npos);
  EXPECT_EQ(help_entry(cal.out, "--out"), "");  // calibrate prints JSON
}

}  // namespace
}  // namespace rdyn::validate
