#include "validate/io/progress_meter.hpp"

#include <chrono>
#include <cmath>
#include <utility>

#include <fmt/format.h>

namespace rdyn::validate {

namespace {
double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "unknown";
  const long s = std::lround(seconds);
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

ProgressMeter::ProgressMeter(std::string label, long total, bool terminal)
    : label_(std::move(label)), total_(total), terminal_(terminal) {}

std::string ProgressMeter::text(long done, double now_s) const {
  std::string t = fmt::format("{}: {}/{} cases ({:.0f} %)", label_, done, total_,
                              total_ > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total_) : 100.0);
  // A rate needs a case done and time measured; before that there is nothing to extrapolate.
  if (done > 0 && now_s > 0) {
    const double rate = static_cast<double>(done) / now_s;
    t += fmt::format(", {:.3g} cases/s", rate);
    if (done < total_) t += ", " + format_duration(static_cast<double>(total_ - done) / rate) + " left";
  }
  return t;
}

std::optional<std::string> ProgressMeter::line_due(long done, double now_s) {
  const bool last = done >= total_;
  const double interval = terminal_ ? kTerminalInterval_s : kLogInterval_s;
  // In a log, the end is the summary line's to report; on a terminal the counter is completed.
  if (!terminal_ && last) return std::nullopt;
  if (!last && now_s - last_s_ < interval) return std::nullopt;
  last_s_ = now_s;
  if (terminal_) return "\r\033[K" + text(done, now_s) + (last ? "\n" : "");
  return text(done, now_s) + "\n";
}

StderrProgress::StderrProgress(std::string label, long total, bool terminal)
    : meter_(std::move(label), total, terminal), start_s_(steady_now_s()) {}

double StderrProgress::elapsed_s() const { return steady_now_s() - start_s_; }

void StderrProgress::done(long count) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto line = meter_.line_due(count, elapsed_s())) {
    std::fputs(line->c_str(), stderr);
    std::fflush(stderr);
  }
}

}  // namespace rdyn::validate
