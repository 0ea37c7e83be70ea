// Plain records of a validation run (validate/harness/run_record.hpp): RunRecord::error_of reads
// the peak-relative error of a quantity and is +∞ for a run that has none (a stopped run, a
// quantity not compared); label() names model, grid, interpolation (or the fit built),
// energy-consistent flag and integrator with its tolerance or step (validate/harness/harness.cpp).
#include "validate/harness/run_record.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace rdyn::validate {
namespace {

SignalError signal(const std::string& name, double peak, double max_abs) {
  SignalError s;
  s.name = name;
  s.peak = peak;
  s.max_rel = max_abs / peak;
  s.rms_rel = 0.5 * max_abs / peak;
  return s;
}

TEST(RunRecord, ErrorOfIsTheMaxErrorRelativeToThePeak) {
  RunRecord r;
  r.model = "reduced";
  // qdot peaks at 8 rad/s and is off by 0.004 rad/s at worst: 5e-4 of its peak.
  r.errors.signals = {signal("qdot", 8.0, 0.004), signal("knee_force", 250.0, 2.5)};
  EXPECT_DOUBLE_EQ(r.error_of("qdot"), 5e-4);
  EXPECT_DOUBLE_EQ(r.error_of("knee_force"), 1e-2);
}

TEST(RunRecord, ErrorOfIsInfiniteForARunWithoutErrors) {
  RunRecord stopped;
  stopped.model = "reduced";
  stopped.failure = "integrator stopped at t = 0.3 s";
  EXPECT_EQ(stopped.error_of("qdot"), std::numeric_limits<double>::infinity());
  // A quantity the comparison does not hold, and a non-finite entry, are no error either.
  RunRecord r;
  r.errors.signals = {signal("qdot", 8.0, 0.004)};
  r.errors.signals.push_back({"F", 0.0, std::nan(""), std::nan("")});
  EXPECT_EQ(r.error_of("F_unknown"), std::numeric_limits<double>::infinity());
  EXPECT_EQ(r.error_of("F"), std::numeric_limits<double>::infinity());
  // So a stopped run never ranks above one that finished with a large error.
  EXPECT_GT(stopped.error_of("qdot"), r.error_of("qdot"));
}

TEST(RunRecord, LabelNamesModelGridInterpolationAndIntegrator) {
  RunRecord full;
  full.model = "full";
  full.integrator = "rkmerson";
  full.tolerance = 1e-6;
  EXPECT_EQ(full.label(), "full rkmerson tol 1e-06");

  RunRecord red;
  red.model = "reduced";
  red.grid_deg = 10;
  red.interpolation = "fourier";
  red.integrator = "rk8pd";
  red.tolerance = 1e-8;
  EXPECT_EQ(red.label(), "reduced 10° fourier rk8pd tol 1e-08");
  red.energy_consistent = true;
  red.fit = "cubic (not-a-knot)";  // the interpolant built, when it differs from the request
  EXPECT_EQ(red.label(), "reduced 10° cubic (not-a-knot)+ec rk8pd tol 1e-08");

  RunRecord fixed = red;
  fixed.fit.clear();
  fixed.energy_consistent = false;
  fixed.grid_deg = 2.5;
  fixed.interpolation = "cubic";
  fixed.integrator = "rk4-fixed";
  fixed.fixed_step_s = 5e-4;
  EXPECT_EQ(fixed.label(), "reduced 2.5° cubic rk4 h=0.5 ms");

  RunRecord peer;
  peer.model = "mujoco";
  peer.integrator = "RK4";
  peer.fixed_step_s = 1e-4;
  EXPECT_EQ(peer.label(), "mujoco RK4 h=0.1 ms");
}

}  // namespace
}  // namespace rdyn::validate
