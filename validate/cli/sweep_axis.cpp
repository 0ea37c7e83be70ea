#include "validate/cli/sweep_axis.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/cli/decimal_number.hpp"

namespace rdyn::validate {

SweepAxis parse_sweep_axis(const std::string& text) {
  auto fail = [&](const std::string& msg) { throw models::SceneError("", 0, "--vary " + text, msg); };
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) fail("expected key=a:b:n");
  SweepAxis a;
  a.key = text.substr(0, eq);
  const std::string range = text.substr(eq + 1);
  // a, b and n as decimal numbers, as every other number (validate/cli/decimal_number.hpp).
  std::vector<std::string> parts;
  for (size_t at = 0;; ) {
    const auto colon = range.find(':', at);
    parts.push_back(range.substr(at, colon == std::string::npos ? std::string::npos : colon - at));
    if (colon == std::string::npos) break;
    at = colon + 1;
  }
  if (parts.size() != 3) fail("expected a:b:n with finite a, b and a whole n ≥ 1");
  for (size_t k = 0; k < 3; ++k) {
    const std::string why = check_decimal_number(parts[k], k == 2);
    if (!why.empty()) fail(std::string(k == 0 ? "a" : k == 1 ? "b" : "n") + " of a:b:n: " + why);
  }
  const double lo = std::strtod(parts[0].c_str(), nullptr), hi = std::strtod(parts[1].c_str(), nullptr);
  errno = 0;
  const long n = std::strtol(parts[2].c_str(), nullptr, 10);
  if (errno == ERANGE || n < 1 || !std::isfinite(lo) || !std::isfinite(hi))
    fail("expected a:b:n with finite a, b and a whole n ≥ 1");
  if (n > 100000) fail("at most 100000 values per axis");
  for (long i = 0; i < n; ++i) a.values.push_back(n == 1 ? lo : lo + (hi - lo) * i / (n - 1));
  return a;
}

}  // namespace rdyn::validate
