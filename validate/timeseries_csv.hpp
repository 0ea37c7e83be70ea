// timeseries.csv: t,q,qdot,qddot,energy,work,F_<name>... (SI units, radians).
#pragma once

#include <string>

#include "engine/forward_dynamics.hpp"

namespace rdyn::validate {

// Writes the series; throws OutputError when the file cannot be written.
void write_timeseries_csv(const std::string& path, const engine::TimeSeries& ts);

// Energy-balance residual max|E(t) − E(0) − W(t)| over the series [J], and the largest
// energy magnitude seen (its natural scale) [J].
struct EnergyBalance {
  double max_residual_J = 0.0;
  double energy_scale_J = 0.0;
};
EnergyBalance energy_balance(const engine::TimeSeries& ts);

}  // namespace rdyn::validate
