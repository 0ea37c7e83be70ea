// Runs an external program (gnuplot) without a shell (issue #9, "no shell ever sees user
// text"): posix_spawnp with an argument vector, a working folder, standard input from
// /dev/null, standard output and error appended to a log, and a wall-time limit.
#pragma once

#include <string>
#include <vector>

namespace rdyn::validate {

struct ProgramResult {
  bool started = false;    // false: the program was not found or could not be spawned
  bool timed_out = false;  // killed after the limit
  int exit_code = -1;      // when it exited normally
  std::string error;       // why it did not start, or how it ended abnormally
  bool ok() const { return started && !timed_out && exit_code == 0; }
};

ProgramResult run_program(const std::vector<std::string>& argv, const std::string& working_dir,
                          const std::string& log_file, double time_limit_s);

}  // namespace rdyn::validate
