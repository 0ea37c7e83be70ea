// timeseries.csv: t,q,qdot,qddot,energy,work,F_<name>... (SI units, radians).
#pragma once

#include <string>

#include "engine/forward_dynamics.hpp"

namespace rdyn::validate {

// Writes the series; throws OutputError when the file cannot be written.
void write_timeseries_csv(const std::string& path, const engine::TimeSeries& ts);

// Energy-balance residual (one implementation, models/timeseries.hpp).
using models::EnergyBalance;
using models::energy_balance;

}  // namespace rdyn::validate
