// Wall-clock timing by repeats up to a minimum total, so a 50 µs run is timed over thousands
// of microseconds and a 2 s run is not repeated needlessly.
#pragma once

#include <functional>
#include <vector>

namespace rdyn::validate {

struct RepeatPolicy {
  int min_repeats = 3;
  int max_repeats = 200;     // bound: a run that is fast but noisy still stops
  double min_total_s = 0.2;  // repeat until this much wall time has been spent
};

// Calls `run` until both min_repeats and min_total_s are reached (or max_repeats); returns
// each call's wall time [s].
std::vector<double> time_repeats(const std::function<void()>& run, const RepeatPolicy& policy);

// Median of the values (the middle pair's mean for an even count); NaN when empty.
double median(std::vector<double> v);

}  // namespace rdyn::validate
