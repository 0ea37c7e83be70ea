#include "validate/harness/ladder_plan.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

namespace rdyn::validate {

long LadderPlan::reduced_runs() const {
  return static_cast<long>(grids_deg.size() * variants.size() *
                           (rk8pd_tolerances.size() + (rkck ? 1 : 0) + fixed_steps_s.size()));
}

LadderPlan plan_ladders(const TimeScale& scale, bool quick) {
  LadderPlan p;
  if (quick) {
    p.full = {{"rkmerson", 1e-5}, {"rkmerson", 1e-7}};
    p.grids_deg = {30, 10, 5};
    p.variants = {{"cubic", false}, {"fourier", false}};
    p.rk8pd_tolerances = {1e-8};
  } else {
    // Every Simbody integrator over a tolerance ladder, so the full-model baseline is the
    // cheapest Simbody offers at each accuracy (issue #11: fair baselines). Measured on the
    // bicycle (knee error, steps): RK3 1e-7 1.7e-5 in 6420 steps (RK-Merson 1e-7: 5.1e-6 in 692),
    // CPodes 1e-8 7.5e-4 in 60593 steps (1e-7: 1.8e-4 in 1801): rungs that are never the
    // cheapest at their accuracy and cost minutes of repeats are left out.
    for (double t : {1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9}) p.full.push_back({"rkmerson", t});
    for (double t : {1e-4, 1e-5, 1e-6}) p.full.push_back({"rk3", t});
    for (double t : {1e-4, 1e-5, 1e-6, 1e-7}) p.full.push_back({"cpodes", t});
    p.grids_deg = {30, 20, 10, 5, 2, 1, 0.5};
    p.variants = {{"cubic", false},   {"akima", false}, {"linear", false},
                  {"fourier", false}, {"cubic", true},  {"fourier", true}};
    p.rk8pd_tolerances = {1e-6, 1e-8, 1e-10};
    p.rkck = true;
    p.extraction_repeats_10deg = 3;
  }
  p.fixed_steps_s = calc_fixed_step_ladder(scale, quick);
  p.peer_steps_s = calc_peer_step_ladder(scale, quick);
  // Timings: the median of repeats until a minimum wall time, so a 50 µs run is not timed once.
  p.full_repeats = quick ? RepeatPolicy{1, 50, 0.0} : RepeatPolicy{3, 50, 0.3};
  p.peer_repeats = p.full_repeats;
  p.reduced_repeats = quick ? RepeatPolicy{1, 200, 0.02} : RepeatPolicy{3, 200, 0.1};
  return p;
}

LadderPlan with_grid(LadderPlan plan, double grid_deg) {
  auto& g = plan.grids_deg;
  if (std::none_of(g.begin(), g.end(), [&](double x) { return std::abs(x - grid_deg) < 1e-9; })) {
    g.push_back(grid_deg);
    std::sort(g.begin(), g.end(), std::greater<double>());
  }
  return plan;
}

}  // namespace rdyn::validate
