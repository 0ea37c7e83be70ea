#include "validate/analysis/cycle_run.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "validate/analysis/confirm_full.hpp"
#include "validate/analysis/mechanism_run.hpp"

namespace rdyn::validate {

CycleStart calc_last_cycle(const models::TimeSeries& run, double fallback_s) {
  const size_t n = run.t.size();
  if (n < 2 || run.q.size() != n || run.qdot.size() != n)
    throw std::invalid_argument("calc_last_cycle: a run of at least two rows");
  if (!(fallback_s > 0)) throw std::invalid_argument("calc_last_cycle: the fallback must be > 0");
  const double direction = run.q.back() >= run.q.front() ? 1.0 : -1.0;
  const auto crossings = calc_revolution_times(run, direction);
  double t0 = run.t.back() - std::min(fallback_s, run.t.back() - run.t.front());
  double duration = 0.0;
  if (crossings.size() >= 2) {
    t0 = crossings[crossings.size() - 2];
    duration = crossings.back() - t0;
  }
  // The first row at or after t0: an exact state of the run.
  size_t r = static_cast<size_t>(std::lower_bound(run.t.begin(), run.t.end(), t0 - 1e-12) - run.t.begin());
  r = std::min(r, n - 2);
  if (crossings.size() < 2) duration = run.t.back() - run.t[r];
  return {run.t[r], run.q[r], run.qdot[r], duration, crossings.size() >= 2};
}

models::TimeSeries simulate_cycle(const models::Scene& scene, const CycleStart& c, int intervals) {
  if (!(c.duration_s > 0) || intervals < 1) throw std::invalid_argument("simulate_cycle: a cycle of positive length");
  models::Scene s = scene;
  s.initial = models::Initial{c.q, c.qdot};
  auto ts = simulate_every_joint(s, "full", c.duration_s, c.duration_s / intervals);
  for (double& t : ts.t) t += c.t_s;
  return ts;
}

}  // namespace rdyn::validate
