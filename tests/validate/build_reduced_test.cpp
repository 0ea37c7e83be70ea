// extract_from_full: the table and its timing by stage (summary.json extraction_stages_ms).
#include "validate/build_reduced.hpp"

#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

void expect_stages_add_up(const Extraction& e) {
  EXPECT_GT(e.stages.system_build_ms, 0.0);
  EXPECT_GT(e.stages.assembly_ms, 0.0);
  EXPECT_GT(e.stages.kinetostatics_ms, 0.0);
  EXPECT_NEAR(e.stages.system_build_ms + e.stages.assembly_ms + e.stages.kinetostatics_ms, e.extraction_ms,
              1e-9 * e.extraction_ms);
}

TEST(BuildReduced, PeriodicExtractionTimesEachStage) {
  const auto e = extract_from_full(models::load_scene("bicycle"), 10, reduced::Method::Kinetostatic);
  EXPECT_EQ(e.samples.q.size(), 36u);
  EXPECT_FALSE(e.range);
  expect_stages_add_up(e);
  // One projection per grid point plus a few per switch angle (4 angles): the separate calls
  // needed 99.
  EXPECT_LE(e.calls, 36 + 4 * 4);
}

TEST(BuildReduced, RangeExtractionTimesEachStage) {
  // A rocker: the full-turn attempt meets a dead point, the range comes from the dead points.
  const auto e = extract_from_full(models::load_scene("fourbar-rocker"), 10, reduced::Method::Kinetostatic);
  ASSERT_TRUE(e.range);
  EXPECT_FALSE(e.samples.periodic);
  expect_stages_add_up(e);
}

}  // namespace
}  // namespace rdyn::validate
