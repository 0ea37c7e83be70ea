// Command-line numbers read as scene numbers: decimal only, a literal beyond a double refused as
// typed; and every number option of a CLI11 command gets that check (validate/cli/cli_options.hpp).
#include "validate/cli/decimal_number.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "validate/cli/cli_options.hpp"

namespace rdyn::validate {
namespace {

TEST(DecimalNumber, PlainDecimalsPassAndTheRestIsRefusedAsTyped) {
  for (const char* ok : {"1", "-2.5", "+.5", "3.", "1e-3", "2.5E+4", "0", "0.0e-999", "1e-300", "nan", "-inf"})
    EXPECT_EQ(check_decimal_number(ok), "") << ok;
  EXPECT_NE(check_decimal_number("0x10").find("expected a decimal number, got '0x10' (digits 0-9 only"),
            std::string::npos);
  for (const char* bad : {"0b11", "0o7", "0x1p3", "1_000", "1'000", "1,5", "", " 1", "1 ", "e3", "1e", "--1"})
    EXPECT_NE(check_decimal_number(bad), "") << bad;
  EXPECT_EQ(check_decimal_number("1e-400"),
            "'1e-400' is out of range: it underflows (below 2.22507e-308 in magnitude, it would read as 0); write 0 "
            "if zero is meant");
  EXPECT_NE(check_decimal_number("-1e400").find("'-1e400' is out of range: beyond the largest double"),
            std::string::npos);
  // Whole numbers: digits only (CLI11 itself refuses one beyond the option's type).
  EXPECT_EQ(check_decimal_number("256", true), "");
  for (const char* bad : {"0x10", "1e3", "2.0", "nan"}) EXPECT_NE(check_decimal_number(bad, true), "") << bad;
  EXPECT_EQ(read_decimal_number("-2.5e1"), -25.0);
  EXPECT_THROW(read_decimal_number("0x10"), std::invalid_argument);
}

TEST(DecimalNumber, EveryNumberOptionOfACommandAndItsGroupsIsChecked) {
  CLI::App app{"test"};
  double duration = 0, tolerance = 0;
  int threads = 0;
  std::string name;
  auto* sub = app.add_subcommand("simulate");
  sub->add_option("--duration", duration);
  sub->add_option("--name", name);
  sub->add_option_group("full")->add_option("--tolerance", tolerance);
  app.add_subcommand("sweep")->add_option_function<int>("--threads", [&](const int& v) { threads = v; });
  require_decimal_numbers(app);
  auto parse = [&](std::vector<std::string> args) -> std::string {
    std::reverse(args.begin(), args.end());  // CLI11 takes a vector in reverse order
    try {
      app.parse(args);
    } catch (const CLI::ParseError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(parse({"simulate", "--duration", "2.5", "--name", "0x10", "--tolerance", "1e-9"}), "");
  EXPECT_EQ(duration, 2.5);
  EXPECT_EQ(name, "0x10");  // text options are text
  EXPECT_NE(parse({"simulate", "--duration", "0x10"}).find("--duration: expected a decimal number, got '0x10'"),
            std::string::npos);
  EXPECT_NE(parse({"simulate", "--tolerance", "1e-400"}).find("--tolerance: '1e-400' is out of range: it underflows"),
            std::string::npos);
  EXPECT_NE(parse({"sweep", "--threads", "0x4"}).find("--threads: expected a whole decimal number"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
