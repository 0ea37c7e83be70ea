#include "validate/harness/timing.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>

namespace rdyn::validate {
namespace {

TEST(Timing, RepeatsUntilTheMinimumWallTime) {
  int calls = 0;
  const auto walls = time_repeats(
      [&] {
        ++calls;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      },
      {3, 1000, 0.03});
  EXPECT_EQ(static_cast<int>(walls.size()), calls);
  // 2 ms calls until 30 ms: at least 15 (one fewer would be under the minimum), not hundreds.
  double total = 0;
  for (double w : walls) total += w;
  EXPECT_GE(total, 0.03);
  EXPECT_LT(total - walls.back(), 0.03);
  EXPECT_GE(calls, 3);
}

TEST(Timing, MinAndMaxRepeatsBound) {
  int calls = 0;
  time_repeats([&] { ++calls; }, {5, 1000, 0.0});
  EXPECT_EQ(calls, 5);  // fast runs: the minimum count
  calls = 0;
  time_repeats(
      [&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        ++calls;
      },
      {1, 4, 10.0});
  EXPECT_EQ(calls, 4);  // the bound holds even when the minimum time is far away
}

TEST(Timing, Median) {
  EXPECT_EQ(median({3, 1, 2}), 2);
  EXPECT_EQ(median({4, 1, 3, 2}), 2.5);
  EXPECT_TRUE(std::isnan(median({})));
}

}  // namespace
}  // namespace rdyn::validate
