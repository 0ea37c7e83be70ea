// `--vary key=a:b:n`: one sweep axis read from its command-line text.
#include "validate/cli/sweep_axis.hpp"

#include <gtest/gtest.h>

#include "models/scene.hpp"

namespace rdyn::validate {
namespace {

// (The suite keeps its name from validate/analysis/sweep_test.cpp, where the reader used to live.)
TEST(Sweep, AxesParseAndRejectBadRanges) {
  const auto a = parse_sweep_axis("bicycle_leg.subject.height_m=1.6:1.9:4");
  EXPECT_EQ(a.key, "bicycle_leg.subject.height_m");
  ASSERT_EQ(a.values.size(), 4u);
  EXPECT_DOUBLE_EQ(a.values[0], 1.6);
  EXPECT_DOUBLE_EQ(a.values[3], 1.9);
  EXPECT_THROW(parse_sweep_axis("x=1:2"), models::SceneError);
  EXPECT_THROW(parse_sweep_axis("x=1:2:0"), models::SceneError);
  EXPECT_THROW(parse_sweep_axis("=1:2:3"), models::SceneError);
  EXPECT_THROW(parse_sweep_axis("x=1:nan:3"), models::SceneError);
}

}  // namespace
}  // namespace rdyn::validate
