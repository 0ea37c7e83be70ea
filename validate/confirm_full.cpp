#include "validate/confirm_full.hpp"

#include <algorithm>
#include <cmath>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"

namespace rdyn::validate {

namespace {
constexpr double kTwoPi = 2 * M_PI;
}

std::vector<double> calc_by_angle(std::vector<std::pair<double, double>> pts) {
  for (auto& p : pts) p.first = std::fmod(std::fmod(p.first, kTwoPi) + kTwoPi, kTwoPi);
  std::sort(pts.begin(), pts.end());
  std::vector<double> out(360, NAN);
  if (pts.empty()) return out;
  for (int a = 0; a < 360; ++a) {
    const double th = a * M_PI / 180;
    auto it = std::lower_bound(pts.begin(), pts.end(), std::make_pair(th, -HUGE_VAL));
    const auto& hi = it == pts.end() ? pts.front() : *it;
    const auto& lo = it == pts.begin() ? pts.back() : *(it - 1);
    double span = hi.first - lo.first, off = th - lo.first;
    if (span <= 0) span += kTwoPi;
    if (off < 0) off += kTwoPi;
    out[a] = lo.second + (hi.second - lo.second) * std::min(1.0, off / span);
  }
  return out;
}

FullConfirmation calc_steady_window(const models::TimeSeries& ts, double skip_s, int force) {
  FullConfirmation c;
  const size_t n = ts.t.size();
  size_t i1 = 0;
  while (i1 < n && ts.t[i1] < skip_s) ++i1;
  if (i1 + 2 >= n) return c;
  const bool has_force = force >= 0 && static_cast<size_t>(force) < ts.forces.size();

  // Over the window's rows: the mean rate from its ends, q̇'s spread over its mean, the peak |F|.
  c.mean_rate_hz = (ts.q.back() - ts.q[i1]) / (kTwoPi * (ts.t.back() - ts.t[i1]));
  double lo = INFINITY, hi = -INFINITY, sum = 0;
  for (size_t i = i1; i < n; ++i) lo = std::min(lo, ts.qdot[i]), hi = std::max(hi, ts.qdot[i]), sum += ts.qdot[i];
  c.speed_fluctuation = (hi - lo) / (sum / (n - i1));
  if (has_force) {
    c.peak_force_N = 0.0;
    for (size_t i = i1; i < n; ++i) c.peak_force_N = std::max(c.peak_force_N, std::abs(ts.forces[force][i]));
  }

  // Whole revolutions: time where q reaches q0 + 2π·k (linear between output rows).
  const double q0 = ts.q[i1];
  const long revs = static_cast<long>(std::floor((ts.q.back() - q0) / kTwoPi));
  if (revs < 1) return c;
  auto crossing = [&](long k, size_t& at) {
    const double target = q0 + kTwoPi * k;
    size_t i = i1;
    while (i + 1 < n && ts.q[i + 1] < target) ++i;
    at = i;
    const double f = (target - ts.q[i]) / (ts.q[i + 1] - ts.q[i]);
    return ts.t[i] + f * (ts.t[i + 1] - ts.t[i]);
  };
  size_t i_end = 0, i_prev = 0;
  const double t_end = crossing(revs, i_end);
  crossing(revs - 1, i_prev);
  c.cadence_hz = revs / (t_end - ts.t[i1]);
  if (has_force) {
    // The last whole revolution, by angle.
    std::vector<std::pair<double, double>> pts;
    for (size_t i = i_prev; i <= i_end + 1 && i < n; ++i) pts.push_back({ts.q[i], ts.forces[force][i]});
    c.force_1deg = calc_by_angle(std::move(pts));
  }
  return c;
}

FullConfirmation confirm_full(const models::Scene& scene, const FullConfirmOptions& opt) {
  const engine::FullModel full(scene);
  engine::ForwardOptions fo;
  fo.duration_s = opt.duration_s;
  fo.output_interval_s = opt.output_interval_s;
  fo.tolerance = opt.tolerance;
  return calc_steady_window(engine::simulate_full(full, fo), opt.skip_s, opt.force);
}

}  // namespace rdyn::validate
