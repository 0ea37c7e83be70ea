// Synthetic run records for the stage tests: a model, a cost and errors, nothing else.
#pragma once

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "validate/harness/run_record.hpp"

namespace rdyn::test {

inline validate::RunRecord record(const std::string& model, double wall_s,
                                  const std::vector<std::pair<std::string, double>>& errors) {
  validate::RunRecord r;
  r.model = model;
  r.integrator = model == "full" ? "rkmerson" : "rk8pd";
  r.tolerance = 1e-8;
  r.grid_deg = model == "full" ? 0.0 : 10.0;
  r.interpolation = model == "full" ? "" : "fourier";
  r.wall_s = wall_s;
  r.per_simulated_s = wall_s;
  for (const auto& [q, e] : errors) r.errors.signals.push_back({q, 1.0, e, e});
  return r;
}

}  // namespace rdyn::test
