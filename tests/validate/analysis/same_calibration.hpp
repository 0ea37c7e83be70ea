// Two calibrations of one scene by two routes (a lent or a column-selected table against the
// whole one) that must agree bit for bit: every value a calibration reports.
#pragma once

#include <gtest/gtest.h>

#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate::test {

inline void expect_same_calibration(const CalibrationResult& a, const CalibrationResult& b) {
  EXPECT_EQ(b.load_value, a.load_value);
  EXPECT_EQ(b.resistance_coefficient, a.resistance_coefficient);
  EXPECT_EQ(b.mean_cadence_hz_reduced, a.mean_cadence_hz_reduced);
  EXPECT_EQ(b.mean_power_w, a.mean_power_w);
  EXPECT_EQ(b.peak_force_N, a.peak_force_N);
  EXPECT_EQ(b.peak_forces_N, a.peak_forces_N);
  EXPECT_EQ(b.speed_fluctuation, a.speed_fluctuation);
  EXPECT_EQ(b.steady_q, a.steady_q);
  EXPECT_EQ(b.steady_qdot, a.steady_qdot);
}

}  // namespace rdyn::validate::test
