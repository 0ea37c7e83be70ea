#include "validate/analysis/unstable_rest.hpp"

#include <algorithm>
#include <cmath>

namespace rdyn::validate {

std::optional<UnstableRest> find_unstable_rest(const models::TimeSeries& ts) {
  const size_t n = std::min({ts.t.size(), ts.q.size(), ts.qdot.size(), ts.qddot.size()});
  double v_max = 0.0, a_max = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (std::isfinite(ts.qdot[i])) v_max = std::max(v_max, std::abs(ts.qdot[i]));
    if (std::isfinite(ts.qddot[i])) a_max = std::max(a_max, std::abs(ts.qddot[i]));
  }
  if (!(v_max > 0) || !(a_max > 0)) return std::nullopt;  // no motion at all: nothing to part
  const double v_rest = kRestFraction * v_max, a_rest = kRestFraction * a_max;
  size_t i = 0;
  while (i < n) {
    if (!(std::abs(ts.qdot[i]) < v_rest && std::abs(ts.qddot[i]) < a_rest)) {
      ++i;
      continue;
    }
    size_t j = i;  // the stretch at rest: [i, j)
    while (j < n && std::abs(ts.qdot[j]) < v_rest && std::abs(ts.qddot[j]) < a_rest) ++j;
    if (j - i >= static_cast<size_t>(kMinRestRows)) {
      for (size_t k = j; k < n; ++k)
        if (std::abs(ts.qdot[k]) > 100 * v_rest) return UnstableRest{ts.t[i], ts.t[j - 1], ts.q[j - 1]};
      return std::nullopt;  // at rest to the end (or barely moving): nothing left
    }
    i = j;
  }
  return std::nullopt;
}

}  // namespace rdyn::validate
