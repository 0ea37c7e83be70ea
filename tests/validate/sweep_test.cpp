// Sweeps: the cartesian product of the axes, sharded into blocks whose CSVs concatenate.
#include "validate/sweep.hpp"

#include <gtest/gtest.h>

#include "models/scene.hpp"

namespace rdyn::validate {
namespace {

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

TEST(Sweep, ShardsConcatenateToTheWholeSweep) {
  SweepOptions o;
  o.scene = "bicycle";
  o.axes = {parse_sweep_axis("bicycle_leg.hip_torque_Nm=60:60:1"), parse_sweep_axis("bicycle_leg.crank_length_m=0.16:0.18:3")};
  o.threads = 2;
  const std::string whole = run_sweep(o, false);
  std::string parts;
  o.shards = 2;
  for (o.shard = 0; o.shard < 2; ++o.shard) parts += run_sweep(o, false);
  EXPECT_EQ(parts, whole);
  // header + 3 cases, all calibrated at 1 Hz, longer cranks needing less torque.
  EXPECT_EQ(std::count(whole.begin(), whole.end(), '\n'), 4);
  EXPECT_EQ(whole.find("error"), whole.find("error\n"));  // only the header's column name
}

}  // namespace
}  // namespace rdyn::validate
