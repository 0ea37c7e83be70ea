// Progress lines on standard error (validate/io/progress.hpp): silent when disabled; enabled, a
// counted "stage [i/n]" line redrawn in place (carriage return, erase line) with its newline
// only when the stage completes, and notes as whole lines.
#include "validate/io/progress.hpp"

#include <gtest/gtest.h>

#include <string>

namespace rdyn::validate {
namespace {

size_t count_of(const std::string& text, char c) {
  size_t n = 0;
  for (char x : text) n += x == c;
  return n;
}

TEST(Progress, DisabledWritesNothing) {
  Progress p(false);
  EXPECT_FALSE(p.enabled());
  testing::internal::CaptureStderr();
  for (long i = 1; i <= 3; ++i) p.count("extract", i, 3);
  p.note("a note");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
}

TEST(Progress, EnabledCountsOnOneLineEndedWhenTheStageCompletes) {
  Progress p(true);
  EXPECT_TRUE(p.enabled());
  testing::internal::CaptureStderr();
  p.count("extract", 1, 3);
  p.count("extract", 2, 3);
  const std::string partial = testing::internal::GetCapturedStderr();
  EXPECT_EQ(partial, "\r\033[Kextract [1/3]\r\033[Kextract [2/3]");
  EXPECT_EQ(count_of(partial, '\n'), 0u);  // still the same terminal line

  testing::internal::CaptureStderr();
  p.count("extract", 3, 3);
  p.note("done");
  const std::string last = testing::internal::GetCapturedStderr();
  EXPECT_EQ(last, "\r\033[Kextract [3/3]\ndone\n");
}

// A count past the end (a stage that overruns its estimate) still ends its line.
TEST(Progress, ACountPastTheEndEndsTheLine) {
  Progress p(true);
  testing::internal::CaptureStderr();
  p.count("runs", 5, 4);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "\r\033[Kruns [5/4]\n");
}

}  // namespace
}  // namespace rdyn::validate
