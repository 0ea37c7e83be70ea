// Where a run comes to rest at an unstable equilibrium and later leaves it: from there, when
// and which way it leaves is decided by differences far below any model's accuracy. No Simbody.
#pragma once

#include <optional>

#include "models/timeseries.hpp"

namespace rdyn::validate {

struct UnstableRest {
  double t_from_s = 0.0, t_to_s = 0.0;  // the rows at rest
  double q = 0.0;                        // where [rad or m]
};

// A stretch of at least kMinRestRows output rows over which |q̇| and |q̈| both stay below
// kRestFraction of their largest values over the run, followed by a row where |q̇| is back above
// 100× that: the motion crept up to an equilibrium (q̇ decays exponentially toward a saddle, as
// a crank driven just short of passing its top does) and fell off it. A reversal of an
// oscillation does not qualify: there q̇ crosses zero within one row with |q̈| large. Rest at a
// stable equilibrium that lasts to the end of the run does not either: nothing parts there.
// Measured: the bicycle with a 0.001 kg·m² flywheel creeps to q = 11.6° from t ≈ 0.3 s and falls
// back at t = 0.69 s in the full model, 0.93 s in the reduced one (q agreed to 1.3e-8 until then).
std::optional<UnstableRest> find_unstable_rest(const models::TimeSeries& ts);

inline constexpr double kRestFraction = 1e-3;
inline constexpr int kMinRestRows = 5;

}  // namespace rdyn::validate
