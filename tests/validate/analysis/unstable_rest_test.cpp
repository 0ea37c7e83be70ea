// find_unstable_rest: a run that creeps to a saddle and falls off is found; a reversal of an
// oscillation and a rest that lasts are not.
#include "validate/analysis/unstable_rest.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace rdyn::validate {
namespace {

// Near a saddle of ẍ = λ² x the motion x = A e^{λt} + B e^{−λt} from B < 0 toward the saddle at
// x = 0 with an energy deficit A < 0 creeps toward it as e^{−λt} and falls back as e^{λt}.
models::TimeSeries saddle(double lambda, double A, double B, double dt, int n) {
  models::TimeSeries ts;
  for (int i = 0; i < n; ++i) {
    const double t = i * dt, ep = A * std::exp(lambda * t), em = B * std::exp(-lambda * t);
    ts.t.push_back(t);
    ts.q.push_back(ep + em);
    ts.qdot.push_back(lambda * (ep - em));
    ts.qddot.push_back(lambda * lambda * (ep + em));
  }
  return ts;
}

TEST(UnstableRest, ACreepToASaddleAndAFallBackIsFound) {
  // B = −1, A = −1e-10 (λ = 1): |q̇| = |A e^t + e^{−t}| and |q̈| = |A e^t − e^{−t}| are both below
  // 1e-3 of their peak 1 for t in (ln 1e3, ln 1e7) = (6.91, 16.1) s; the fall back passes
  // |q̇| = 0.1 at t = ln 1e9 = 20.7 s, and the run ends at 22 s, before |q̇| exceeds its start.
  const auto ts = saddle(1.0, -1e-10, -1.0, 0.05, 441);
  const auto r = find_unstable_rest(ts);
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->t_from_s, std::log(1e3), 0.06);
  EXPECT_NEAR(r->t_to_s, std::log(1e7), 0.06);
  EXPECT_NEAR(r->q, 0.0, 2e-3);  // at the saddle
}

TEST(UnstableRest, AnOscillationsReversalsAndALastingRestAreNot) {
  models::TimeSeries osc;  // q = sin t: q̇ crosses zero with |q̈| at its largest
  for (int i = 0; i < 2000; ++i) {
    const double t = i * 0.01;
    osc.t.push_back(t), osc.q.push_back(std::sin(t)), osc.qdot.push_back(std::cos(t)), osc.qddot.push_back(-std::sin(t));
  }
  EXPECT_FALSE(find_unstable_rest(osc));
  // Exactly on the separatrix (A = 0): it creeps to the saddle and stays to the end of the run.
  EXPECT_FALSE(find_unstable_rest(saddle(1.0, 0.0, -1.0, 0.05, 600)));
  // The same creep cut before it falls back (|q̇| 0.018 at 19 s): nothing parted within the run.
  EXPECT_FALSE(find_unstable_rest(saddle(1.0, -1e-10, -1.0, 0.05, 381)));
  // A deficit too large to rest (A = −1e-6 > 1e-3²): it reverses at t = 6.9 s with |q̈| = 2e-3.
  EXPECT_FALSE(find_unstable_rest(saddle(1.0, -1e-6, -1.0, 0.05, 281)));
  EXPECT_FALSE(find_unstable_rest(models::TimeSeries{}));
}

}  // namespace
}  // namespace rdyn::validate
