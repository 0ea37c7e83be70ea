// Error against grid step, per interpolation, with the observed order of convergence.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "validate/harness/run_record.hpp"

namespace rdyn::validate {

struct ConvergenceSeries {
  std::string interpolation;
  std::vector<std::pair<double, double>> points;  // (grid [deg], error / peak), coarse to fine
  double order = 0.0;                             // NaN when fewer than two points above the floor
};

// Least-squares slope of log(error) against log(grid) over the errors above `floor` (the
// reference's own accuracy: below it the error measures the reference, not the table).
double calc_observed_order(const std::vector<std::pair<double, double>>& points, double floor);

// For each interpolation (plain m2, rk8pd at `tolerance`): the errors of `quantity` at each
// grid of the ladder and their observed order.
std::vector<ConvergenceSeries> calc_convergence(const std::vector<RunRecord>& runs,
                                                const std::string& quantity, double tolerance,
                                                double floor);

}  // namespace rdyn::validate
