// rdyn benchmarks (Google Benchmark; not part of ctest). Run:
//   cmake --build build --target rdyn_bench && build/rdyn_bench
// Bicycle scene; the full and reduced settings are the ones `rdyn validate` finds at
// matched knee-force accuracy (≤ 0.1 % of its peak against the converged reference).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "engine/kinetostatic.hpp"
#include "engine/mujoco_peer.hpp"
#include "engine/reduced_source.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/extract.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"

namespace {

using namespace rdyn;

const models::Scene& bicycle() {
  static const models::Scene s = models::load_scene("bicycle");
  return s;
}

const reduced::Samples& samples(double grid_deg) {
  static std::map<double, reduced::Samples> cache;
  auto it = cache.find(grid_deg);
  if (it != cache.end()) return it->second;
  engine::FullModel model(bicycle());
  engine::FullKinetostaticSource src(model);
  reduced::ExtractOptions o;
  o.step_rad = grid_deg * M_PI / 180;
  return cache[grid_deg] = reduced::extract_samples(src, bicycle(), o);
}

const reduced::ReducedModel& model(double grid_deg) {
  static std::map<double, reduced::ReducedModel> cache;
  auto it = cache.find(grid_deg);
  if (it != cache.end()) return it->second;
  return cache[grid_deg] = reduced::make_reduced_model(samples(grid_deg), bicycle(), reduced::Interpolation::Fourier);
}

// One evaluation of Eksergian's right-hand side (fused table lookup + loads).
void BM_ReducedRhs(benchmark::State& st) {
  const auto& m = model(10);
  reduced::ReducedWorkspace ws(m);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> q(0, 2 * M_PI);
  double qs[256];
  for (double& x : qs) x = q(rng);
  // 1000 evaluations per iteration: Debian's libbenchmark is a debug build whose
  // per-iteration overhead would swamp a ~25 ns operation.
  for (auto _ : st)
    for (size_t i = 0; i < 1000; ++i) {
      double qdd, p;
      reduced::calc_acceleration(m, ws, qs[i & 255], 6.28, qdd, p);
      benchmark::DoNotOptimize(qdd);
    }
  st.counters["s_per_rhs"] = benchmark::Counter(1000.0 * st.iterations(),
                                                benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ReducedRhs)->Unit(benchmark::kMicrosecond);

// One allocation-free fixed RK4 step (real-time stepper).
void BM_ReducedFixedStep(benchmark::State& st) {
  const auto& m = model(10);
  reduced::ReducedWorkspace ws(m);
  ws.q = 0, ws.qdot = 6.28;
  reduced::init_gates(m, ws);
  for (auto _ : st)
    for (int i = 0; i < 1000; ++i) {
      reduced::step_fixed_rk4(m, ws, 5e-3);
      benchmark::DoNotOptimize(ws.q);
    }
  st.counters["s_per_step"] = benchmark::Counter(1000.0 * st.iterations(),
                                                 benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ReducedFixedStep)->Unit(benchmark::kMicrosecond);

// Reduced simulation with the validation's outputs (every 5 ms), per simulated second.
void BM_ReducedPerSimulatedSecond(benchmark::State& st) {
  const auto& m = model(static_cast<double>(st.range(0)));
  reduced::ReducedOptions o;
  o.duration_s = 10;
  o.output_interval_s = 0.005;
  o.tolerance = 1e-6;
  for (auto _ : st) benchmark::DoNotOptimize(reduced::simulate_reduced(m, 0, 2 * M_PI, o).q.back());
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ReducedPerSimulatedSecond)->Arg(10)->Arg(5)->Unit(benchmark::kMicrosecond);

// One crank revolution of the reduced model (no outputs): the steady-cycle unit of work.
void BM_ReducedPerRevolution(benchmark::State& st) {
  const auto& m = model(10);
  reduced::AdaptiveIntegrator integ(m, 1e-8);
  for (auto _ : st) {
    integ.reset(0, 0, 2 * M_PI);
    benchmark::DoNotOptimize(integ.advance(10.0, 2 * M_PI));
  }
}
BENCHMARK(BM_ReducedPerRevolution)->Unit(benchmark::kMicrosecond);

// Table extraction (kinetostatic, 10°), reported per grid point.
void BM_ExtractionPerGridPoint(benchmark::State& st) {
  reduced::ExtractOptions o;
  o.step_rad = 10 * M_PI / 180;
  for (auto _ : st) {
    engine::FullModel model(bicycle());
    engine::FullKinetostaticSource src(model);
    benchmark::DoNotOptimize(reduced::extract_samples(src, bicycle(), o).q.size());
  }
  st.counters["s_per_grid_point"] = benchmark::Counter(36.0 * st.iterations(),
                                                       benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ExtractionPerGridPoint)->Unit(benchmark::kMillisecond);

// Full-model forward dynamics (Simbody), per simulated second, at tolerance 1e-6 (the
// cheapest full run within 0.1 % knee-force error) and at the 1e-10 reference.
void BM_FullPerSimulatedSecond(benchmark::State& st) {
  engine::FullModel full(bicycle());
  engine::ForwardOptions o;
  o.duration_s = 1.0;
  o.output_interval_s = 0.005;
  o.tolerance = st.range(0) == 6 ? 1e-6 : 1e-10;
  for (auto _ : st) benchmark::DoNotOptimize(engine::simulate_full(full, o).q.back());
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FullPerSimulatedSecond)->Arg(6)->Arg(10)->Unit(benchmark::kMillisecond);

// The same over 5 s with one output at the end (the fair baseline of `rdyn validate`: the output
// grid does not cap Simbody's step), RK-Merson at 1e-4…1e-6 (range: −log10 tolerance).
void BM_FullFairPerSimulatedSecond(benchmark::State& st) {
  engine::FullModel full(bicycle());
  engine::ForwardOptions o;
  o.duration_s = 5.0;
  o.output_interval_s = 5.0;
  o.tolerance = std::pow(10.0, -static_cast<double>(st.range(0)));
  long steps = 0;
  for (auto _ : st) steps = engine::simulate_full(full, o).stats.steps_taken;
  st.counters["steps"] = static_cast<double>(steps);
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FullFairPerSimulatedSecond)->Arg(4)->Arg(5)->Arg(6)->Unit(benchmark::kMillisecond);

// MuJoCo (peer) on the bicycle, 5 s with 5 ms outputs, per simulated second: range(0) 0 Euler,
// 1 RK4; range(1) the step in µs.
void BM_MujocoPerSimulatedSecond(benchmark::State& st) {
  if (!engine::mujoco_available()) {
    st.SkipWithError("rdyn was built without MuJoCo");
    return;
  }
  engine::FullModel full(bicycle());
  engine::FullWorkspace ws(full);
  const auto k = engine::calc_kinetostatic(full, ws, bicycle().initial.q, bicycle().initial.qdot, 0, engine::Loads::Off);
  engine::MujocoSettings ms;
  ms.integrator = st.range(0) == 0 ? "euler" : "rk4";
  ms.timestep_s = engine::calc_peer_step(st.range(1) * 1e-6, 0.005);
  const engine::MujocoModel m(bicycle(), k.joint_q, ms);
  engine::MujocoRunOptions o;
  o.duration_s = 5.0;
  o.output_interval_s = 0.005;
  o.initial_u = k.joint_u;
  for (auto _ : st) benchmark::DoNotOptimize(engine::simulate_mujoco(m, o).q.back());
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MujocoPerSimulatedSecond)
    ->Args({0, 1000})
    ->Args({0, 100})
    ->Args({1, 1000})
    ->Args({1, 100})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
