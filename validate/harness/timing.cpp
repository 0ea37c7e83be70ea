#include "validate/harness/timing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace rdyn::validate {

std::vector<double> time_repeats(const std::function<void()>& run, const RepeatPolicy& p) {
  using Clock = std::chrono::steady_clock;
  std::vector<double> walls;
  double total = 0;
  while (static_cast<int>(walls.size()) < std::max(1, p.max_repeats) &&
         (static_cast<int>(walls.size()) < p.min_repeats || total < p.min_total_s)) {
    const auto t0 = Clock::now();
    run();
    walls.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    total += walls.back();
  }
  return walls;
}

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace rdyn::validate
