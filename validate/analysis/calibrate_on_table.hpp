// calibrate()'s reduced part on a table a sweep keeps for its next cases, without copying it.
#pragma once

#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {

// calibrate_reduced on the reduced model of `table` and with_unit_load(table_scene, opt), checked
// on `case_scene` (as a sweep case: its table may carry reaction lines the case did not ask for).
// The model borrows table.table instead of copying it (a 0.25°-resampled fourier table, ~1 MB:
// the copy and its fresh pages were ~0.7 ms of a sweep case over the rider's height, issue #28)
// and gives it back, unchanged — the calibration reads the table and never writes it — also when
// the calibration throws. Only when building the model itself throws is table.table left empty
// (the caller then drops its table). The result equals
// calibrate_reduced(make_reduced_model(table.samples, with_unit_load(table_scene, opt), table.table), ...).
CalibrationResult calibrate_on_table(CalibrationTable& table, const models::Scene& table_scene,
                                     const models::Scene& case_scene, const CalibrationOptions& opt,
                                     Progress& progress);

}  // namespace rdyn::validate
