// Progress of a long run: when a line is due (times passed in, not measured) and what it says.
#include "validate/io/progress_meter.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

namespace rdyn::validate {
namespace {

TEST(ProgressMeter, DurationsReadAsPeopleSayThem) {
  EXPECT_EQ(format_duration(0.4), "0 s");
  EXPECT_EQ(format_duration(59.4), "59 s");
  EXPECT_EQ(format_duration(274), "4 min 34 s");
  EXPECT_EQ(format_duration(2 * 3600 + 5 * 60 + 10), "2 h 05 min");
  EXPECT_EQ(format_duration(-1), "unknown");
  EXPECT_EQ(format_duration(std::numeric_limits<double>::infinity()), "unknown");
}

// 120 of 1000 cases in 40 s: 3 cases/s, 880 left at 3 cases/s is 293 s.
TEST(ProgressMeter, LineGivesCountRateAndTimeLeft) {
  const ProgressMeter m("sweep shard 2/8", 1000, false);
  EXPECT_EQ(m.text(120, 40.0), "sweep shard 2/8: 120/1000 cases (12 %), 3 cases/s, 4 min 53 s left");
  EXPECT_EQ(m.text(0, 5.0), "sweep shard 2/8: 0/1000 cases (0 %)");  // nothing to extrapolate yet
  EXPECT_EQ(m.text(1000, 500.0), "sweep shard 2/8: 1000/1000 cases (100 %), 2 cases/s");
}

// In a log a line at most every 30 s and none at the end (the summary line reports it); one case
// a second for 100 s gives lines at 30, 60 and 90 s.
TEST(ProgressMeter, LogGetsALineEveryThirtySeconds) {
  ProgressMeter m("sweep", 100, false);
  std::vector<long> at;
  for (long k = 1; k <= 100; ++k)
    if (const auto line = m.line_due(k, static_cast<double>(k))) {
      at.push_back(k);
      EXPECT_EQ(line->back(), '\n');
      EXPECT_EQ(line->find('\r'), std::string::npos);
    }
  EXPECT_EQ(at, (std::vector<long>{30, 60, 90}));
}

// On a terminal the line is rewritten at most every 0.2 s and completed by the last item.
TEST(ProgressMeter, TerminalRewritesOneLineAndEndsIt) {
  ProgressMeter m("sweep", 10, true);
  int lines = 0;
  for (long k = 1; k <= 10; ++k) {  // ten items in 0.1 s: only the last is due (at 0.01 s none is)
    const auto line = m.line_due(k, 0.01 * static_cast<double>(k));
    if (!line) continue;
    ++lines;
    EXPECT_EQ(line->rfind("\r\033[K", 0), 0u);
    EXPECT_EQ(k, 10);
    EXPECT_EQ(line->back(), '\n');
  }
  EXPECT_EQ(lines, 1);
  ProgressMeter slow("sweep", 10, true);
  EXPECT_TRUE(slow.line_due(1, 0.3).has_value());
  EXPECT_FALSE(slow.line_due(2, 0.4).has_value());
  EXPECT_TRUE(slow.line_due(3, 0.6).has_value());
}

}  // namespace
}  // namespace rdyn::validate
