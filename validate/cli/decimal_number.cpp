#include "validate/cli/decimal_number.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <regex>
#include <stdexcept>

namespace rdyn::validate {

std::string check_decimal_number(const std::string& text, bool whole) {
  const std::string shown = text.size() > 40 ? text.substr(0, 40) + "…" : text;
  std::string lower = text;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  const std::string bare = !lower.empty() && (lower[0] == '+' || lower[0] == '-') ? lower.substr(1) : lower;
  if (!whole && (bare == "nan" || bare == "inf" || bare == "infinity")) return "";  // the range check names it
  static const std::regex decimal(R"([+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?)");
  static const std::regex integer(R"([+-]?[0-9]+)");
  if (!std::regex_match(text, whole ? integer : decimal))
    return fmt::format("expected a {} number, got '{}'{}", whole ? "whole decimal" : "decimal", shown,
                       bare.rfind("0x", 0) == 0 || bare.rfind("0b", 0) == 0 || bare.rfind("0o", 0) == 0
                           ? " (digits 0-9 only, as in a scene: no hexadecimal, binary or octal)"
                           : "");
  if (whole) return "";  // CLI11 refuses a whole number beyond its type, naming the option
  errno = 0;
  const double v = std::strtod(text.c_str(), nullptr);
  if (std::isinf(v))
    return fmt::format("'{}' is out of range: beyond the largest double ({:g}) in magnitude", shown,
                       std::numeric_limits<double>::max());
  // A nonzero literal below the smallest normal double reads as 0 or a denormal that lost its
  // digits (as the scene reader refuses it).
  const std::string mantissa = text.substr(0, text.find_first_of("eE"));
  if (std::abs(v) < std::numeric_limits<double>::min() && mantissa.find_first_of("123456789") != std::string::npos)
    return fmt::format("'{}' is out of range: it underflows (below {:g} in magnitude, it would read as {:g}); write 0 "
                       "if zero is meant",
                       shown, std::numeric_limits<double>::min(), v);
  return "";
}

double read_decimal_number(const std::string& text) {
  const std::string why = check_decimal_number(text);
  if (!why.empty()) throw std::invalid_argument(why);
  return std::strtod(text.c_str(), nullptr);
}

}  // namespace rdyn::validate
