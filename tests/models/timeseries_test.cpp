// The output grid and the energy balance of a run (models/timeseries.hpp) against hand counts.
#include "models/timeseries.hpp"

#include <gtest/gtest.h>

namespace rdyn::models {
namespace {

TEST(Timeseries, TheGridEndsAtTheDurationWithoutASliverRow) {
  // 1 s at 0.3 s: 0.3, 0.6, 0.9 and the duration itself; 1 s at 0.1 s: ten rows although
  // 1/0.1 = 10.000000000000002 in floating point.
  EXPECT_EQ(calc_output_rows(1.0, 0.3), 4);
  EXPECT_DOUBLE_EQ(calc_output_time(3, 4, 1.0, 0.3), 0.3 * 3);
  EXPECT_EQ(calc_output_time(4, 4, 1.0, 0.3), 1.0);
  EXPECT_EQ(calc_output_rows(1.0, 0.1), 10);
  EXPECT_EQ(calc_output_time(10, 10, 1.0, 0.1), 1.0);
  EXPECT_EQ(calc_output_rows(5.0, 0.01), 500);
}

TEST(Timeseries, TheEnergyBalanceIsTheLargestResidualAndWhereItIs) {
  TimeSeries ts;
  ts.t = {0.0, 0.5, 1.0};
  ts.energy = {10.0, 9.0, 7.5};
  ts.work = {0.0, -0.9, -2.0};  // residuals 0, 0.1, 0.5
  const auto eb = energy_balance(ts);
  EXPECT_DOUBLE_EQ(eb.max_residual_J, 0.5);
  EXPECT_EQ(eb.worst_time_s, 1.0);
  EXPECT_EQ(eb.energy_scale_J, 10.0);
}

}  // namespace
}  // namespace rdyn::models
