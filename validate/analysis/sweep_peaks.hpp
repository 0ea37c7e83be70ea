// A sweep's peak columns (`rdyn sweep --peak COLUMN`, issue #23 item 4): the largest |value| of
// any output column of a case's reduced run — a constraint force, a joint reaction, the shaking
// load, a joint's motion — over the window the sweep's other peaks come from: a calibrating
// sweep's steady cycle (one period from the operating point), a drive sweep's revolution.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "reduced/reduced_model.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {

// Rows per steady cycle a calibrating sweep's peak columns are taken from (0.25° of a turn, as
// the steady cycle's own sampling, reduced::SteadyCycleOptions::samples). Unlike its peak force,
// the rows are not refined between samples: a smooth peak is low by about (π/N)²/2 of its value
// per harmonic order squared (2.4e-6 at N = 1440 for the first).
inline constexpr int kPeakCycleRows = 1440;

// The scene whose joint outputs a reduced run gives: `reactions: all` becomes the reactions the
// reduced model can give (as `rdyn simulate --model reduced` does); any other scene is itself.
models::Scene reduced_joint_output_scene(const models::Scene& scene);

// The columns of a sweep case's run, t left out: a calibrating sweep's are timeseries.csv's (q,
// qdot, qddot, energy, work, F_<force>…, the joint outputs the scene requests), a drive sweep's
// `rdyn drive`'s (q, qdot, qddot, drive_Nm, drive_W, F_<force>…, the joint outputs).
std::vector<std::string> peak_column_candidates(const models::Scene& scene, bool drive);

// Checks the --peak names before any case runs: each named once and each a candidate. A
// models::SceneError on field --peak (exit 2) lists the candidates; for a joint output of a
// joint the scene has but does not request, it names the outputs key that asks for it.
void check_peak_columns(const models::Scene& scene, const std::vector<std::string>& peaks, bool drive);

// The scene a case's table is extracted from and its reduced model built on: the scene itself,
// or, when a peak column is a joint output, reduced_joint_output_scene with the reaction lines
// those outputs need (reduced::with_reaction_requests; its TableError when it cannot give them).
models::Scene peak_table_scene(const models::Scene& scene, const std::vector<std::string>& peaks);

// The table columns a sweep case reads on the table of peak_table_scene(scene, peaks): its reduced
// model's (reduced::reduced_model_columns), and with joint-output peaks the joint columns
// (reduced::joint_output_columns). The constraint lines, joint ratios and joint positions no case
// reads are neither kept nor fitted (issue #28 item 3: the fit was ~14 % of such a case).
std::vector<std::string> sweep_table_columns(const models::Scene& scene, const std::vector<std::string>& peaks);

// Whether a peak column is a joint output (the run needs reduced::add_joint_outputs).
bool peaks_need_joint_outputs(const models::Scene& scene, const std::vector<std::string>& peaks);

// Max |value| over the rows of each named column, in the order of `peaks`: `names` are the run's
// columns in order and column(k) the k-th. Throws models::NumericalError on a non-finite value
// (never NaN in an output) and std::invalid_argument on a name the run lacks.
std::vector<double> calc_column_peaks(const std::vector<std::string>& names,
                                      const std::function<const std::vector<double>&(size_t)>& column,
                                      const std::vector<std::string>& peaks);

// One steady cycle of a calibrated case as `rdyn simulate --model reduced` writes it: the model
// of `table_scene` (peak_table_scene of the case's scene) on `table` at the operating point r,
// from (steady_q, steady_qdot) over one period 1/mean_cadence_hz_reduced, kPeakCycleRows rows
// at the calibration's tolerance, with the joint outputs of `scene` when `joint_outputs`.
models::TimeSeries simulate_steady_cycle(const models::Scene& scene, const models::Scene& table_scene,
                                         const CalibrationTable& table, const CalibrationOptions& opt,
                                         const CalibrationResult& r, bool joint_outputs);

// The peak columns of a calibrated case over that cycle, in the order of `peaks`.
std::vector<double> calc_steady_cycle_peaks(const models::Scene& scene, const models::Scene& table_scene,
                                            const CalibrationTable& table, const CalibrationOptions& opt,
                                            const CalibrationResult& r, const std::vector<std::string>& peaks);

}  // namespace rdyn::validate
