#include "validate/analysis/confirm_full.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"

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

std::vector<double> calc_revolution_times(const models::TimeSeries& ts, double direction) {
  std::vector<double> times;
  const size_t n = ts.t.size();
  if (n < 2) return times;
  const double s = direction < 0 ? -1.0 : 1.0;
  // Work with p = s·q, which increases on average.
  const double p0 = s * ts.q[0];
  size_t i = 0;
  for (long k = 1;; ++k) {
    const double target = p0 + kTwoPi * k;
    while (i + 1 < n && s * ts.q[i + 1] < target) ++i;
    if (i + 1 >= n) break;
    // Cubic Hermite on [t_i, t_{i+1}] through (p, ṗ) at both ends: p(0) < target ≤ p(1), so
    // bisection keeps a crossing inside its bracket.
    const double h = ts.t[i + 1] - ts.t[i];
    const double a = s * ts.q[i], b = s * ts.q[i + 1], va = s * ts.qdot[i] * h, vb = s * ts.qdot[i + 1] * h;
    auto p = [&](double x) {
      const double x2 = x * x, x3 = x2 * x;
      return (2 * x3 - 3 * x2 + 1) * a + (x3 - 2 * x2 + x) * va + (-2 * x3 + 3 * x2) * b + (x3 - x2) * vb;
    };
    double lo = 0.0, hi = 1.0;
    if (!(a < target)) hi = 0.0;  // the row itself (the first row of a level already reached)
    for (int it = 0; it < 60 && hi - lo > 1e-15; ++it) {
      const double mid = 0.5 * (lo + hi);
      (p(mid) < target ? lo : hi) = mid;
    }
    times.push_back(ts.t[i] + hi * h);
  }
  return times;
}

RevolutionMeasures calc_revolution_measures(const models::TimeSeries& ts, double direction, int m, int force) {
  RevolutionMeasures r;
  if (ts.t.empty() || m < 1) return r;
  std::vector<double> t = calc_revolution_times(ts, direction);
  r.revolutions = static_cast<int>(t.size());
  t.insert(t.begin(), ts.t.front());  // t[k]: the end of revolution k, t[0] the start
  const int n = r.revolutions;
  if (n < m) return r;
  r.cadence_hz = m / (t[n] - t[n - m]);
  if (n >= 2 * m) r.previous_cadence_hz = m / (t[n - m] - t[n - 2 * m]);
  // Rows of the last m revolutions (the rows between their crossings).
  const double s = direction < 0 ? -1.0 : 1.0;
  const bool has_force = force >= 0 && static_cast<size_t>(force) < ts.forces.size();
  double lo = INFINITY, hi = -INFINITY, sum = 0, peak = 0;
  long rows = 0;
  for (size_t i = 0; i < ts.t.size(); ++i) {
    if (ts.t[i] < t[n - m] || ts.t[i] > t[n]) continue;
    const double v = s * ts.qdot[i];
    lo = std::min(lo, v), hi = std::max(hi, v), sum += v, ++rows;
    if (has_force) peak = std::max(peak, std::abs(ts.forces[force][i]));
  }
  if (rows > 0) {
    r.speed_fluctuation = (hi - lo) / (sum / rows);
    if (has_force) r.peak_force_N = peak;
  }
  return r;
}

SteadyConfirmation confirm_full_steady(const models::Scene& scene, const SteadyConfirmOptions& opt) {
  if (!(opt.cadence_hz > 0 && std::isfinite(opt.cadence_hz) && opt.revolutions >= 1 &&
        opt.max_duration_s > 0 && std::isfinite(opt.max_duration_s) && opt.steady_tolerance > 0))
    throw std::invalid_argument("confirm_full_steady: cadence, revolutions, cap and tolerance must be positive");
  const engine::FullModel full(scene);
  engine::ForwardOptions fo;
  fo.output_interval_s = opt.output_interval_s;
  fo.tolerance = opt.tolerance;
  fo.domain = engine::calc_independent_domain(full);  // once for every run
  const double direction = scene.initial.qdot < 0 ? -1.0 : 1.0;
  SteadyConfirmation c;
  // 2m + 1 periods of the reduced cycle (2 % more), doubled until steady or at the cap.
  double duration = std::min(opt.max_duration_s, 1.02 * (2 * opt.revolutions + 1) / opt.cadence_hz);
  for (;;) {
    fo.duration_s = duration;
    c.measures = calc_revolution_measures(engine::simulate_full(full, fo), direction, opt.revolutions, opt.force);
    c.duration_s = duration;
    ++c.runs;
    const double a = c.measures.cadence_hz, b = c.measures.previous_cadence_hz;
    c.steady = std::isfinite(a) && std::isfinite(b) && std::abs(a - b) <= opt.steady_tolerance * std::abs(a);
    if (c.steady || duration >= opt.max_duration_s) return c;
    duration = std::min(opt.max_duration_s, 2 * duration);
  }
}

}  // namespace rdyn::validate
