// rdyn benchmarks (Google Benchmark; not part of ctest). Run:
//   cmake --build build --target rdyn_bench && build/rdyn_bench
// Bicycle scene; the full and reduced settings are the ones `rdyn validate` finds at
// matched knee-force accuracy (≤ 0.1 % of its peak against the converged reference).
#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <optional>
#include <string>
#include <vector>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "engine/kinetostatic.hpp"
#include "engine/mujoco_peer.hpp"
#include "engine/reduced_source.hpp"
#include "models/scene_source.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/extract.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "reduced/steady_cycle.hpp"
#include "engine/independent_range.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/calibrate_on_table.hpp"
#include "validate/analysis/sweep_peaks.hpp"

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

const reduced::ReducedModel& cubic_model(double grid_deg) {
  static std::map<double, reduced::ReducedModel> cache;
  auto it = cache.find(grid_deg);
  if (it != cache.end()) return it->second;
  return cache[grid_deg] =
             reduced::make_reduced_model(samples(grid_deg), bicycle(), reduced::Interpolation::CubicSpline);
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

// CPU seconds per call of f, over n calls (the process clock: this machine is shared).
template <typename F>
double cpu_seconds_per_call(long n, F&& f) {
  timespec a{}, b{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &a);
  for (long i = 0; i < n; ++i) f(i);
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &b);
  return ((b.tv_sec - a.tv_sec) + 1e-9 * (b.tv_nsec - a.tv_nsec)) / n;
}

// Cost of the reduced model's two kernels on a run's own states (q, q̇) in the order the run
// visits them: one right-hand side (calc_acceleration) and one output sample (calc_sample). The
// states matter: past the first turn the periodic lookup wraps its interval index, and the
// loads' branches (gates, Coulomb signs) follow the run; a sweep over q ∈ [0, 2π) at fixed q̇,
// as the floor was first measured, skips the wrap and measured 20–25 % cheaper. `chained`:
// each call's q depends on the previous result (as an integrator's stages do), so its latency
// is measured instead of its throughput.
struct KernelCost {
  double rhs_s = 0, sample_s = 0, rhs_chained_s = 0;
};
KernelCost calc_kernel_cost(const reduced::ReducedModel& m, const models::TimeSeries& run) {
  reduced::ReducedWorkspace ws(m);
  reduced::init_gates(m, ws);
  std::vector<double> f(m.force_names.size());
  const long n = static_cast<long>(run.t.size()), calls = std::max(200000L, n);
  double sink = 0;
  KernelCost c;
  c.rhs_s = cpu_seconds_per_call(calls, [&](long i) {
    double qdd, p;
    reduced::calc_acceleration(m, ws, run.q[i % n], run.qdot[i % n], qdd, p);
    sink += qdd;
  });
  c.sample_s = cpu_seconds_per_call(calls, [&](long i) {
    double qdd, p;
    sink += reduced::calc_sample(m, ws, run.q[i % n], run.qdot[i % n], qdd, p, f.data());
  });
  double carry = 0;
  c.rhs_chained_s = cpu_seconds_per_call(calls, [&](long i) {
    double qdd, p;
    reduced::calc_acceleration(m, ws, run.q[i % n] + 1e-300 * carry, run.qdot[i % n], qdd, p);
    carry = qdd;
  });
  benchmark::DoNotOptimize(sink);
  benchmark::DoNotOptimize(carry);
  return c;
}

// Reduced simulation with the validation's outputs (every 5 ms), per simulated second, next to
// its floor (issue #11 item 6): the steps it takes times the right-hand sides one step of its
// method needs (rk8pd: 13 stages; RK4: 4) plus the output samples times one output evaluation
// (one fused table lookup: q̈, energy, constraint forces), both measured here on the same model
// at the run's own states (calc_kernel_cost). range(0): grid [deg]; range(1): 0 for rk8pd at
// 1e-6 with the 10 s run's `fourier` table, else the headline's 1 ms RK4 on a cubic table
// (5 s) — the settings the matched-error speedups pick.
void BM_ReducedPerSimulatedSecond(benchmark::State& st) {
  const double grid = static_cast<double>(st.range(0));
  const bool rk4 = st.range(1) != 0;
  const auto& m = rk4 ? cubic_model(grid) : model(grid);
  reduced::ReducedOptions o;
  o.duration_s = rk4 ? 5 : 10;
  o.output_interval_s = 0.005;
  o.tolerance = 1e-6;
  if (rk4) o.integrator = "rk4-fixed", o.fixed_step_s = 1e-3;
  models::TimeSeries ts;
  for (auto _ : st) ts = reduced::simulate_reduced(m, 0, 2 * M_PI, o);
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  const KernelCost k = calc_kernel_cost(m, ts);
  const double per_step = rk4 ? 4.0 : 13.0;
  const double steps = static_cast<double>(ts.stats.steps_attempted), rows = static_cast<double>(ts.t.size());
  st.counters["floor_s_per_simulated_s"] = (per_step * steps * k.rhs_s + rows * k.sample_s) / o.duration_s;
  st.counters["floor_chained_s_per_simulated_s"] = (per_step * steps * k.rhs_chained_s + rows * k.sample_s) / o.duration_s;
  st.counters["steps_per_simulated_s"] = steps / o.duration_s;
  st.counters["rhs_s"] = k.rhs_s;
  st.counters["rhs_chained_s"] = k.rhs_chained_s;
  st.counters["output_sample_s"] = k.sample_s;
}
BENCHMARK(BM_ReducedPerSimulatedSecond)->Args({10, 0})->Args({5, 0})->Args({2, 1})->Args({1, 1})->Unit(benchmark::kMicrosecond);

// The reduced settings `rdyn validate bicycle` matches at the knee errors of its baselines, timed
// like every engine there (5 s, one output at the end): range(0) 0 — 1° fourier with energy-
// consistent m2, RK4 at period/35 (28.2 ms; knee 3.2e-5, within Simbody's 5.8e-5); 1 — 5° cubic,
// RK4 at the ladder's largest step, duration/100 = 50 ms (knee 7.1e-4, within MuJoCo Euler's
// 8.1e-4 at 0.83 ms; MuJoCo RK4's 4.5e-4 takes period/21, 46.9 ms). The period is the
// reference's one revolution at its peak speed, 0.98569 s.
void BM_ReducedMatchedSetting(benchmark::State& st) {
  const bool simbody_match = st.range(0) == 0;
  static const reduced::ReducedModel fine_ec =
      reduced::make_reduced_model(samples(1), bicycle(), reduced::Interpolation::Fourier, true);
  const auto& m = simbody_match ? fine_ec : cubic_model(5);
  reduced::ReducedOptions o;
  o.duration_s = 5.0;
  o.output_interval_s = 5.0;
  o.integrator = "rk4-fixed";
  o.fixed_step_s = simbody_match ? 0.98569 / 35 : 0.05;
  for (auto _ : st) benchmark::DoNotOptimize(reduced::simulate_reduced(m, 0, 2 * M_PI, o).q.back());
}
BENCHMARK(BM_ReducedMatchedSetting)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

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

// The 10° bicycle extraction (what summary.json's extraction_ms times) by stage, CPU time,
// median and range of the repetitions: Simbody system build (FullModel: topology, model stage),
// assembly (FullWorkspace: assembler, one-DOF and branch checks), the kinetostatic sweep
// (extract_samples: 36 grid points, 4 switch angles) and the fourier table fit
// (make_reduced_model). Issue #11 item 3: target ≤ 5 ms for the first three on a quiet machine.
// Process CPU time, not wall time: this machine is shared, and a busy neighbour stretches the wall
// clock threefold (load 8–10 on 2 cores) while the CPU time stays put; on a quiet machine the two agree.
void BM_ExtractionStages(benchmark::State& st) {
  struct clock {
    static double now() {
      timespec t{};
      clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
      return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
    }
  };
  auto ms = [](double a, double b) { return b - a; };
  std::vector<double> build, assembly, sweep, fit, total;
  reduced::ExtractOptions o;
  o.step_rad = 10 * M_PI / 180;
  long calls = 0;
  for (auto _ : st) {
    const auto t0 = clock::now();
    engine::FullModel model(bicycle());
    const auto t1 = clock::now();
    engine::FullKinetostaticSource src(model);
    const auto t2 = clock::now();
    const auto s = reduced::extract_samples(src, bicycle(), o);
    const auto t3 = clock::now();
    benchmark::DoNotOptimize(reduced::make_reduced_model(s, bicycle(), reduced::Interpolation::Fourier).table.coef.data());
    const auto t4 = clock::now();
    build.push_back(ms(t0, t1)), assembly.push_back(ms(t1, t2)), sweep.push_back(ms(t2, t3)), fit.push_back(ms(t3, t4));
    total.push_back(ms(t0, t3));
    calls = src.calls();
  }
  auto put = [&](const std::string& name, std::vector<double> v) {
    std::sort(v.begin(), v.end());
    st.counters[name + "_ms_median"] = v[v.size() / 2];
    st.counters[name + "_ms_min"] = v.front();
    st.counters[name + "_ms_max"] = v.back();
  };
  put("build", build);
  put("assembly", assembly);
  put("sweep", sweep);
  put("fit", fit);
  put("extraction", total);
  st.counters["calls"] = static_cast<double>(calls);
}
BENCHMARK(BM_ExtractionStages)->Iterations(15)->Unit(benchmark::kMillisecond);

// The bicycle's steady cycle (10° fourier table, the scene's loads, section at q = 0) with
// its extremes: by the first integral of Eksergian's equation (Arg 0) and by the time-stepping
// Poincaré map (Arg 1), tolerance 1e-10 as calibration uses.
void BM_SteadyCycle(benchmark::State& st) {
  const auto& m = model(10);
  reduced::SteadyCycleOptions o;
  o.qdot_guess = 2 * M_PI;
  o.tolerance = 1e-10;
  reduced::SteadyCycle c;
  for (auto _ : st)
    c = st.range(0) == 0 ? reduced::calc_steady_cycle(m, o) : reduced::calc_steady_cycle_time_stepping(m, o);
  st.counters["passes"] = c.passes;
  st.counters["steps"] = static_cast<double>(c.steps);
  st.counters["evals"] = static_cast<double>(c.rhs_evaluations);
}
BENCHMARK(BM_SteadyCycle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// One calibration without the full-model confirmation — what one `rdyn sweep` case costs:
// table extraction (10°) plus the reduced part (torque search over steady cycles, the final
// cycle's extremes). BM_ExtractionPerGridPoint × 36 is the extraction's share.
void BM_CalibrationWithoutFullCheck(benchmark::State& st) {
  validate::CalibrationOptions o;
  o.full_max_s = 0.0;
  validate::Progress quiet(false);
  validate::CalibrationResult r;
  for (auto _ : st) r = validate::calibrate(bicycle(), o, quiet);
  st.counters["passes"] = r.evaluations;
}
BENCHMARK(BM_CalibrationWithoutFullCheck)->Unit(benchmark::kMillisecond);

// What one `rdyn sweep` case costs when it changes the mechanism (issue #28 item 3), by stage,
// CPU time per case, medians and ranges over a sweep of 20 rider heights (1.6–1.9 m, each a new
// table) in one thread, as the sweep runs it: the scene (load_scene with the override, the
// bicycle-leg generator), the Simbody system build, the dead-point walk (assembly and
// calc_independent_domain), the 10° extraction, the table fit and the reduced calibration.
// Arg 0: the walk with the singular-point scan (before the edges-only walk); Arg 1: the cold
// route (edges-only walk before every extraction); Arg 2: what the sweep runs now (the scene
// file parsed once, each case's scene a SceneSource load with its override), continuation
// in the parameters — extract_calibration_table with the previous case's neighbour record (the
// walk only where a case's own sweep or its neighbour's comes near rank loss) and only the
// columns a case reads fitted (sweep_table_columns) — whose build, walk, extraction and fit are
// one stage, "table"; `walks` counts the cases that walked.
void BM_SweepCaseStagesOverHeight(benchmark::State& st) {
  auto now = [] {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
  };
  const bool continued = st.range(0) == 2;
  const std::vector<std::string> names =
      continued ? std::vector<std::string>{"scene", "table", "reduced", "case"}
                : std::vector<std::string>{"scene", "build", "walk", "extraction", "fit", "reduced", "case"};
  std::vector<std::vector<double>> ms(names.size());
  constexpr int kCases = 20;
  long walks = 0;
  for (auto _ : st) {
    std::optional<validate::TableNeighbour> neighbour;
    std::optional<models::SceneSource> scenes;  // the sweep's: the file parsed by its first case
    for (int k = 0; k < kCases; ++k) {
      const double h = 1.6 + 0.3 * k / (kCases - 1);
      std::vector<double> t{now()};
      const std::vector<models::Override> height{{"bicycle_leg.subject.height_m", std::to_string(h)}};
      if (continued && !scenes) scenes.emplace("bicycle");
      const auto scene = continued ? scenes->load(height) : models::load_scene("bicycle", height);
      validate::CalibrationOptions o = validate::calibration_options_of(scene, 0.0, 0.0, "");
      o.full_max_s = 0.0;
      t.push_back(now());
      validate::CalibrationTable table;
      if (continued) {
        table = validate::extract_calibration_table(scene, o, neighbour, validate::sweep_table_columns(scene, {}));
        neighbour = validate::neighbour_of(scene, table);
        walks += table.walked ? 1 : 0;
        t.push_back(now());
      } else {
        const engine::FullModel model(scene);
        t.push_back(now());
        { const engine::FullWorkspace assembled(model); }
        benchmark::DoNotOptimize(st.range(0) == 0 ? engine::calc_independent_domain(model).periodic
                                                  : engine::calc_independent_domain_edges(model).periodic);
        t.push_back(now());
        auto e = validate::extract_from_full(model, o.grid_deg, reduced::Method::Kinetostatic);
        t.push_back(now());
        table.table = reduced::build_table(e.samples, reduced::parse_interpolation(o.interpolation));
        table.samples = std::move(e.samples);
        t.push_back(now());
      }
      validate::Progress quiet(false);
      // The sweep's route (Arg 2) lends its table to the reduced model; the cold ones copy it.
      benchmark::DoNotOptimize(continued ? validate::calibrate_on_table(table, scene, scene, o, quiet).load_value
                                         : validate::calibrate(scene, table, o, quiet).load_value);
      t.push_back(now());
      for (size_t i = 0; i + 1 < names.size(); ++i) ms[i].push_back(t[i + 1] - t[i]);
      ms.back().push_back(t.back() - t.front());
    }
  }
  for (size_t i = 0; i < names.size(); ++i) {
    auto v = ms[i];
    std::sort(v.begin(), v.end());
    st.counters[names[i] + "_ms_median"] = v[v.size() / 2];
    st.counters[names[i] + "_ms_min"] = v.front();
    st.counters[names[i] + "_ms_max"] = v.back();
  }
  if (continued) st.counters["walks"] = static_cast<double>(walks) / static_cast<double>(st.iterations());
}
BENCHMARK(BM_SweepCaseStagesOverHeight)->Arg(0)->Arg(1)->Arg(2)->Iterations(3)->Unit(benchmark::kMillisecond);

// Building the fused table with `fourier` interpolation (trigonometric interpolant resampled
// at ≤ 0.25° into the cubic table) from synthetic samples with the bicycle's 21 columns; the
// argument is the grid step in millidegrees (10000 = 10°).
void BM_FourierTableBuild(benchmark::State& st) {
  const int n = static_cast<int>(std::lround(360000.0 / static_cast<double>(st.range(0))));
  reduced::Samples s;
  s.step = 2 * M_PI / n;
  for (int i = 0; i < n; ++i) s.q.push_back(i * s.step);
  for (int c = 0; c < 21; ++c) {
    std::vector<double> v(n);
    for (int i = 0; i < n; ++i) v[i] = (1 + 0.1 * c) * std::exp(std::sin(s.q[i] + c)) + 0.2 * std::cos(3 * s.q[i]);
    s.add("c" + std::to_string(c), v);
  }
  for (auto _ : st) benchmark::DoNotOptimize(reduced::build_table(s, reduced::Interpolation::Fourier).coef.data());
  st.counters["grid_points"] = n;
}
BENCHMARK(BM_FourierTableBuild)->Arg(10000)->Arg(1000)->Arg(500)->Arg(300)->Arg(100)->Arg(50)->Unit(benchmark::kMillisecond);

// Full-model forward dynamics (Simbody), per simulated second, at tolerance 1e-6 (the
// cheapest full run within 0.1 % knee-force error) and at the 1e-10 reference.
void BM_FullPerSimulatedSecond(benchmark::State& st) {
  engine::FullModel full(bicycle());
  engine::ForwardOptions o;
  o.duration_s = 1.0;
  o.output_interval_s = 0.005;
  o.tolerance = st.range(0) == 6 ? 1e-6 : 1e-10;
  o.branch_guard = false;  // Simbody's cost alone, as validate times it
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
  o.branch_guard = false;  // Simbody's cost alone, as validate times it
  long steps = 0;
  for (auto _ : st) steps = engine::simulate_full(full, o).stats.steps_taken;
  st.counters["steps"] = static_cast<double>(steps);
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_FullFairPerSimulatedSecond)->Arg(4)->Arg(5)->Arg(6)->Unit(benchmark::kMillisecond);

// MuJoCo (peer) on the bicycle, 5 s with 5 ms outputs (range(2) 1: one output at the end, as
// `rdyn validate` times it), per simulated second: range(0) 0 Euler, 1 RK4; range(1) the step in µs.
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
  o.output_interval_s = st.range(2) != 0 ? 5.0 : 0.005;  // range(2): one output at the end
  o.initial_u = k.joint_u;
  for (auto _ : st) benchmark::DoNotOptimize(engine::simulate_mujoco(m, o).q.back());
  st.counters["s_per_simulated_s"] = benchmark::Counter(o.duration_s * st.iterations(),
                                                        benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_MujocoPerSimulatedSecond)
    ->Args({0, 1000, 0})
    ->Args({0, 1000, 1})
    ->Args({0, 100, 0})
    ->Args({1, 1000, 0})
    ->Args({1, 1000, 1})
    ->Args({1, 100, 0})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
