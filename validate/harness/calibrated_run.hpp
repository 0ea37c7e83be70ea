// The calibrated operating point from both models (issue #23: the validate report's figures
// showed the scene's own loads, not the operating point its calibration found): the scene with
// the calibrated load (and resistance), started on the reduced steady cycle, run for two
// revolutions by the full model and by the reduced model from the 10° table, on the same rows.
#pragma once

#include <cmath>
#include <optional>
#include <string>

#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "reduced/samples.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {

struct CalibratedRun {
  double cadence_hz = 0.0;  // the calibration's target [rev/s]
  double grid_deg = 10.0;   // the reduced model's table: the calibration's grid (opt.grid_deg)
  models::TimeSeries full, reduced;  // the same t rows: q, q̇, the constraint forces
  std::string force_name;            // the first requested constraint force ("": none)
  // max |reduced − full| over the rows, relative to the full model's peak |·| (NaN: no force).
  double qdot_error = NAN, force_error = NAN;
  double mean_cadence_full_hz = NAN, mean_cadence_reduced_hz = NAN;  // (q_end − q_0) / (2π t_end)
};

// Nothing when the calibration did not hold (unconfirmed, or no steady point) or the 10° table is
// missing. The reduced model runs on the calibration's own grid (the 10° table, or one extracted
// at opt.grid_deg when the scene's validation.calibrate.grid_deg differs). Both runs at tight
// tolerances (full 1e-10, reduced rk8pd 1e-10), rows `dt_s` apart.
// Throws as engine::simulate_full / reduced::simulate_reduced.
std::optional<CalibratedRun> calc_calibrated_run(const models::Scene& scene, const CalibrationOptions& opt,
                                                 const CalibrationResult& r, const reduced::Samples& samples10,
                                                 double dt_s);

}  // namespace rdyn::validate
