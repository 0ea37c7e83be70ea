// Errors of one run against a reference run over the steady cycles.
#pragma once

#include <string>
#include <vector>

#include "models/timeseries.hpp"

namespace rdyn::validate {

// Start of the steady cycles of a reference run and how it was found.
struct SteadyWindow {
  double t_start = 0.0;
  int revolutions = 0;  // whole revolutions after t_start
  bool whole_run = false;  // no steady cycles: compared from t = 0
  std::string how;      // plain-words description for the report
};

// Revolutions are the crossings of q0 + 2πk. The start-up transient ends at the first
// revolution from which every revolution's mean speed differs from the previous one's by
// less than `tolerance` (quasi-steady: a heavy flywheel's slow drift toward its final cadence,
// ~0.3 % per revolution for the bicycle, is not a start-up transient); at least the first
// revolution is skipped. Without three revolutions (a transient, a rocking or stalling
// mechanism) there are no steady cycles: the whole run is compared, and `how` says so.
SteadyWindow detect_steady_window(const models::TimeSeries& ref, bool rotating, double tolerance = 1e-2);

struct SignalError {
  std::string name;     // "qdot" or a constraint force
  double peak = 0.0;    // max |reference| over the window
  double max_rel = 0.0;  // max |run − ref| / peak
  double rms_rel = 0.0;  // RMS(run − ref) / peak
};

struct Comparison {
  // qdot, the constraint forces, the joint outputs both runs carry, then mean_qdot (mean speed)
  std::vector<SignalError> signals;
  long samples = 0;   // compared
  long excluded = 0;  // skipped because a load gate differed (between two switch instants)
  const SignalError* find(const std::string& name) const;
};

// Both runs must share the output times. Samples where the two runs disagree on a load gate
// (one has switched, the other not yet) are excluded: the force jumps there, and the
// comparison would measure the switch-time difference, not the model.
Comparison compare_series(const models::TimeSeries& ref, const models::TimeSeries& run, double t_start);

}  // namespace rdyn::validate
