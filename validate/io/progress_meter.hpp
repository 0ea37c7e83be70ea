// Progress of a long run of counted items (a sweep's cases) on standard error: how many are
// done, the rate and the time left. On a terminal one line is rewritten at most every
// kTerminalInterval_s; otherwise (a Slurm log, a pipe) a new line is written at most every
// kLogInterval_s, so a log of a day-long run stays a few hundred lines. The clock is passed in
// (seconds since the start), so what is printed when is a function of its inputs.
#pragma once

#include <cstdio>
#include <mutex>
#include <optional>
#include <string>

namespace rdyn::validate {

// "42 s", "4 min 05 s", "2 h 05 min": a duration for people.
std::string format_duration(double seconds);

class ProgressMeter {
 public:
  static constexpr double kTerminalInterval_s = 0.2;
  static constexpr double kLogInterval_s = 30.0;

  // `label` starts every line ("sweep 2/8"); `total` items are expected.
  ProgressMeter(std::string label, long total, bool terminal);

  // The text to print now that `done` items are done at `now_s`, or nothing when the last line
  // is too recent. On a terminal it starts with a carriage return and clears the line, and the
  // last item ends it with a line break; in a log every line ends with one.
  std::optional<std::string> line_due(long done, double now_s);

  // The line itself: "sweep 2/8: 120/1000 cases (12 %), 3.21 cases/s, 4 min 34 s left".
  std::string text(long done, double now_s) const;

 private:
  std::string label_;
  long total_;
  bool terminal_;
  double last_s_ = 0.0;
};

// A ProgressMeter on standard error, safe to call from worker threads, timed by the steady clock.
class StderrProgress {
 public:
  StderrProgress(std::string label, long total, bool terminal);
  void done(long count);  // `count` items are done (from any thread)
  double elapsed_s() const;

 private:
  ProgressMeter meter_;
  std::mutex mutex_;
  double start_s_;
};

}  // namespace rdyn::validate
