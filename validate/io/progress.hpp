// Progress on the terminal for long runs: one counted line per stage on a TTY (standard
// error), silent when standard error is not a terminal (CI logs, pipes).
#pragma once

#include <unistd.h>

#include <cstdio>
#include <string>

namespace rdyn::validate {

class Progress {
 public:
  explicit Progress(bool enabled = isatty(STDERR_FILENO) != 0) : enabled_(enabled) {}
  void count(const std::string& stage, long i, long n) {
    if (!enabled_) return;
    std::fprintf(stderr, "\r\033[K%s [%ld/%ld]", stage.c_str(), i, n);
    if (i >= n) std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  void note(const std::string& line) {
    if (enabled_) std::fprintf(stderr, "%s\n", line.c_str());
  }
  bool enabled() const { return enabled_; }

 private:
  bool enabled_;
};

}  // namespace rdyn::validate
