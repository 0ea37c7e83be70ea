#include "validate/thresholds.hpp"

#include <gtest/gtest.h>

#include "tests/validate/run_records.hpp"

namespace rdyn::validate {
namespace {

using test::record;

TEST(Thresholds, JudgedOnTheMatchingTightRun) {
  std::vector<RunRecord> runs{record("reduced", 1e-3, {{"qdot", 4e-3}}),
                              record("reduced", 1e-3, {{"qdot", 6e-3}}),
                              record("reduced", 1e-3, {{"qdot", 1e-4}})};
  runs[0].tolerance = 1e-10;  // the tight fourier run at 10°: the one judged
  runs[1].tolerance = 1e-8;   // same grid, looser: not judged
  runs[2].tolerance = 1e-10, runs[2].interpolation = "cubic";  // other interpolation
  const models::Threshold th{"qdot", 10.0, "", 5e-3};
  auto t = judge_threshold(th, runs, 1e-10);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->error, 4e-3);
  EXPECT_TRUE(t->pass);
  EXPECT_EQ(t->run, runs[0].label());
  // The cubic run when the threshold names cubic; a tighter limit fails.
  t = judge_threshold({"qdot", 10.0, "cubic", 5e-5}, runs, 1e-10);
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->error, 1e-4);
  EXPECT_FALSE(t->pass);
  // A grid outside the ladder: no run to judge on (the harness runs it).
  EXPECT_FALSE(judge_threshold({"qdot", 7.5, "", 1.0}, runs, 1e-10));
}

TEST(Thresholds, AStoppedRunOrAMissingQuantityFails) {
  RunRecord stopped = record("reduced", 1e-3, {});
  stopped.failure = "diverged";
  const auto t = judge_threshold_on({"qdot", 10.0, "", 1e9}, stopped);
  EXPECT_FALSE(t.pass);
  EXPECT_TRUE(std::isinf(t.error));
}

}  // namespace
}  // namespace rdyn::validate
