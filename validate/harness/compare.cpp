#include "validate/harness/compare.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace rdyn::validate {

const SignalError* Comparison::find(const std::string& name) const {
  for (const auto& s : signals)
    if (s.name == name) return &s;
  return nullptr;
}

SteadyWindow detect_steady_window(const models::TimeSeries& ref, bool rotating, double tol) {
  SteadyWindow w;
  const double T = ref.t.back();
  std::vector<double> crossings;  // times where q passes q0 + 2πk
  if (rotating) {
    const double q0 = ref.q.front();
    for (size_t i = 1; i < ref.t.size(); ++i) {
      const double k0 = std::floor((ref.q[i - 1] - q0) / (2 * M_PI) + 1e-12);
      const double k1 = std::floor((ref.q[i] - q0) / (2 * M_PI) + 1e-12);
      if (k1 > k0 && k1 >= 1) {
        const double target = q0 + 2 * M_PI * k1;
        const double f = (target - ref.q[i - 1]) / (ref.q[i] - ref.q[i - 1]);
        crossings.push_back(ref.t[i - 1] + f * (ref.t[i] - ref.t[i - 1]));
      }
    }
  }
  if (crossings.size() < 3) {
    w.t_start = 0.0;
    w.revolutions = static_cast<int>(crossings.size());
    w.whole_run = true;
    w.how = rotating ? fmt::format("fewer than three full revolutions in {:.3g} s, so no steady cycles: compared over "
                                   "the whole run",
                                   T)
                     : fmt::format("the coordinate moves within a range (it does not turn): compared over "
                                   "the whole run of {:.3g} s",
                                   T);
    return w;
  }
  // Mean speed of revolution k (from crossing k−1 to k; the first one starts at t = 0).
  std::vector<double> start{0.0}, mean;
  for (size_t k = 0; k < crossings.size(); ++k) {
    const double t0 = k == 0 ? 0.0 : crossings[k - 1];
    mean.push_back(2 * M_PI / (crossings[k] - t0));
    if (k > 0) start.push_back(t0);
  }
  // Walk back from the last revolution while consecutive means stay within the tolerance.
  size_t first_steady = mean.size() - 1;
  while (first_steady > 0 &&
         std::abs(mean[first_steady] - mean[first_steady - 1]) <= tol * std::abs(mean[first_steady]))
    --first_steady;
  first_steady = std::max<size_t>(first_steady, 1);  // always skip the first revolution
  w.t_start = start[first_steady];
  w.revolutions = static_cast<int>(mean.size() - first_steady);
  w.how = fmt::format(
      "revolution-mean speeds: the start-up transient ends at the first revolution from which consecutive "
      "revolutions' mean speeds differ by less than {:.1g} (always skipping the first revolution): t ≥ {:.3f} s, "
      "{} revolutions compared",
      tol, w.t_start, w.revolutions);
  return w;
}

Comparison compare_series(const models::TimeSeries& ref, const models::TimeSeries& run, double t_start) {
  if (ref.t.size() != run.t.size()) throw std::runtime_error("compared runs have different output times");
  for (size_t i = 0; i < ref.t.size(); ++i)
    if (std::abs(ref.t[i] - run.t[i]) > 1e-9) throw std::runtime_error("compared runs have different output times");
  Comparison c;
  const size_t nf = ref.forces.size();
  std::vector<const std::vector<double>*> a{&ref.qdot}, b{&run.qdot};
  c.signals.push_back({"qdot"});
  for (size_t k = 0; k < nf; ++k) {
    a.push_back(&ref.forces[k]);
    b.push_back(&run.forces[k]);
    c.signals.push_back({ref.force_names[k]});
  }
  // The joint outputs both runs carry (reactions, shaking, joint motions), matched by name.
  const size_t first_joint = a.size();
  for (size_t i = 0; i < ref.column_names.size(); ++i)
    for (size_t j = 0; j < run.column_names.size(); ++j)
      if (ref.column_names[i] == run.column_names[j] && ref.columns[i].size() == ref.t.size() &&
          run.columns[j].size() == run.t.size()) {
        a.push_back(&ref.columns[i]);
        b.push_back(&run.columns[j]);
        c.signals.push_back({ref.column_names[i]});
      }
  std::vector<double> sum2(a.size(), 0.0);
  const bool masks = ref.gates.size() == ref.t.size() && run.gates.size() == run.t.size();
  for (size_t i = 0; i < ref.t.size(); ++i) {
    if (ref.t[i] < t_start - 1e-12) continue;
    if (masks && ref.gates[i] != run.gates[i]) {
      ++c.excluded;
      continue;
    }
    ++c.samples;
    for (size_t s = 0; s < a.size(); ++s) {
      const double d = (*b[s])[i] - (*a[s])[i];
      c.signals[s].peak = std::max(c.signals[s].peak, std::abs((*a[s])[i]));
      // A NaN stays (std::max would drop it): a run with one is never within any error.
      if (std::isnan(d) || std::isnan(c.signals[s].max_rel))
        c.signals[s].max_rel = NAN;
      else
        c.signals[s].max_rel = std::max(c.signals[s].max_rel, std::abs(d));
      sum2[s] += d * d;
    }
  }
  // A joint output that is zero but for rounding (a flywheel's reaction across its own axis,
  // ~1e-11 N beside 200 N elsewhere) has no relative error of its own: its peak counts at least
  // 1e-9 of the largest joint output's.
  double joint_scale = 0.0;
  for (size_t s = first_joint; s < a.size(); ++s) joint_scale = std::max(joint_scale, c.signals[s].peak);
  for (size_t s = first_joint; s < a.size(); ++s)
    if (c.signals[s].peak < 1e-9 * joint_scale) c.signals[s].peak = 1e-9 * joint_scale;
  for (size_t s = 0; s < a.size(); ++s) {
    auto& sig = c.signals[s];
    const double peak = sig.peak > 0 ? sig.peak : 1.0;
    sig.max_rel /= peak;
    sig.rms_rel = c.samples ? std::sqrt(sum2[s] / c.samples) / peak : 0.0;
  }
  // Mean speed over the window, from the displacement: insensitive to the phase that builds
  // up over long runs (pointwise errors then measure the phase, not the model).
  size_t i0 = 0;
  while (i0 < ref.t.size() && ref.t[i0] < t_start - 1e-12) ++i0;
  if (i0 + 1 < ref.t.size() && ref.q.size() == ref.t.size() && run.q.size() == run.t.size()) {
    const double T = ref.t.back() - ref.t[i0];
    const double mean_ref = (ref.q.back() - ref.q[i0]) / T, mean_run = (run.q.back() - run.q[i0]) / T;
    // Relative to the mean speed, or to 1 % of the peak speed when the mean is smaller (an
    // oscillating mechanism: its mean speed is near zero and a relative error of it means nothing).
    const double scale = std::max({std::abs(mean_ref), 0.01 * c.signals[0].peak, 1e-300});
    const double rel = std::abs(mean_run - mean_ref) / scale;
    c.signals.push_back({"mean_qdot", std::abs(mean_ref), rel, rel});
  }
  return c;
}

}  // namespace rdyn::validate
