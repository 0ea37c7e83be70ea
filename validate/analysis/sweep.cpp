#include "validate/analysis/sweep.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

#include <fmt/format.h>

#include "engine/full_model.hpp"
#include "models/scene_hash.hpp"
#include "models/scene_source.hpp"
#include "models/scene_write.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/reduced_model.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/calibrate_on_table.hpp"
#include "validate/analysis/drive.hpp"
#include "validate/analysis/sweep_peaks.hpp"
#include "validate/io/escape.hpp"
#include "validate/io/progress.hpp"

namespace rdyn::validate {

namespace {

// The text the sweep's fingerprint is taken of: everything that decides its rows. The scene is
// its expanded YAML without the file it came from (a node may see the same scene at another
// path); numbers are C99 hex floats (exact); strings are length-prefixed.
std::string sweep_defining_text(const models::Scene& base, const SweepPlan& p) {
  models::Scene scene = base;
  scene.source_file.clear();
  std::string t = "rdyn-sweep v1\n" + models::scene_to_yaml(scene);
  auto str = [&](const std::string& s) { t += fmt::format("{}:{}\n", s.size(), s); };
  for (const auto& a : p.opt.axes) {
    str(a.key);
    for (const double v : a.values) t += fmt::format("{:a} ", v);
    t += "\n";
  }
  const CalibrationOptions& c = p.calibration;
  t += fmt::format("cadence {:a} power {:a} grid {:a}{}\n", c.cadence_hz, c.power_w, c.grid_deg,
                   c.grid_given ? "" : " refined");
  if (p.opt.drive_cadence_hz != 0) t += fmt::format("drive {:a}\n", p.opt.drive_cadence_hz);
  str(p.opt.load);
  str(p.header);
  return t;
}

// What a calibration table depends on: the scene hash, and the loops' branch checks, which the
// hash leaves out (they only refuse an assembly, which a reused table would skip).
std::string table_key(const models::Scene& scene) {
  std::string key = models::scene_hash_hex(models::scene_hash(scene));
  for (const auto& l : scene.loops)
    if (l.branch) key += fmt::format("|{}:{}:{}", l.name, l.branch->joint, l.branch->sign);
  return key;
}

// The order the shard's cases run in, cut into the chunks a thread takes at once: the axes that
// change the mechanism vary slowest (a stable sort of the case indices by their axis digits,
// mechanism axes first), so the cases that share a table follow each other whatever the order
// of --vary (a table is ~85 % of a case that extracts); a chunk holds cases of one mechanism
// only, at most 1/(4·threads) of the shard, so one thread extracts each table and the threads
// still share the work when there are few mechanisms. The rows are still written in case order.
struct RunOrder {
  std::vector<long> cases;   // case indices in run order
  std::vector<long> chunks;  // offsets into `cases` where each chunk starts, then cases.size()
};

RunOrder run_order(const SweepPlan& plan, int threads) {
  const auto& axes = plan.opt.axes;
  const long first = plan.range.first, n = plan.range.end - plan.range.first;
  // Per case: the mechanism axes' digits, then the others' (last axis varies fastest).
  auto digits = [&](long index) {
    std::vector<long> d(axes.size());
    for (size_t i = axes.size(); i-- > 0;) {
      d[i] = index % static_cast<long>(axes[i].values.size());
      index /= static_cast<long>(axes[i].values.size());
    }
    std::vector<long> key;
    for (int pass = 0; pass < 2; ++pass)
      for (size_t i = 0; i < axes.size(); ++i)
        if (plan.changes_mechanism[i] == (pass == 0)) key.push_back(d[i]);
    return key;
  };
  const auto mechanism_digits = static_cast<std::ptrdiff_t>(
      std::count(plan.changes_mechanism.begin(), plan.changes_mechanism.end(), true));
  std::vector<std::pair<std::vector<long>, long>> keyed;
  keyed.reserve(n);
  for (long k = 0; k < n; ++k) keyed.emplace_back(digits(first + k), first + k);
  std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  RunOrder r;
  const long most = std::max(1L, n / (4L * std::max(1, threads)));
  for (long k = 0; k < n; ++k) {
    const bool same_mechanism =
        k > 0 && std::equal(keyed[k].first.begin(), keyed[k].first.begin() + mechanism_digits,
                            keyed[k - 1].first.begin());
    if (!same_mechanism || k - r.chunks.back() >= most) r.chunks.push_back(k);
    r.cases.push_back(keyed[k].second);
  }
  r.chunks.push_back(n);
  return r;
}

// The last table a worker extracted, by table_key: cases that differ only in load values,
// resistance coefficients, cadence or power share it (the extraction and fit are 3/4 of a
// calibrated case; run_order puts the cases of one mechanism next to each other).
struct TableCache {
  std::optional<std::pair<std::string, CalibrationTable>> calibration;
  std::optional<std::pair<std::string, reduced::Samples>> drive;  // a drive sweep's
  long extracted = 0;
  // The last table's neighbour record (issue #28 item 3): a next table of the same topology
  // whose neighbour stayed far from rank loss skips the dead-point walk when its own sweep does
  // too. Cleared by a failed extraction, so the case after a failure walks.
  std::optional<TableNeighbour> neighbour;
  long walks = 0;  // tables whose dead-point walk ran
  // The scene file read and parsed once per worker (the YAML parse was ~12 % of a case that
  // changes the mechanism); each case loads it with its overrides, as load_scene would.
  std::optional<models::SceneSource> scenes;
};

// The peak columns' fields, each followed by its comma ("" without --peak).
std::string peak_fields(const std::vector<double>& peaks) {
  std::string f;
  for (const double p : peaks) f += fmt::format("{:.10g},", p);
  return f;
}

// A calibrated case's fields after its status. With --peak joint outputs the table carries the
// reaction lines they need (the calibration reads m1, m2 and the loads' ratios only: the same).
std::string calibrated_fields(const SweepPlan& plan, const models::Scene& case_scene, TableCache& cache) {
  const models::Scene scene = peak_table_scene(case_scene, plan.opt.peaks);
  const std::string key = table_key(scene);
  if (!cache.calibration || cache.calibration->first != key) {
    cache.calibration.reset();  // a failed extraction leaves none
    ++cache.extracted;
    auto previous = std::move(cache.neighbour);
    cache.neighbour.reset();
    cache.calibration.emplace(key, extract_calibration_table(scene, plan.calibration, previous,
                                                             sweep_table_columns(case_scene, plan.opt.peaks)));
    cache.neighbour = neighbour_of(scene, cache.calibration->second);
    if (cache.calibration->second.walked) ++cache.walks;
  }
  // calibrate()'s reduced part on the model of the table's scene, checked on the case's own (its
  // reaction lines' reserved names are the reduced model's, not the user's).
  Progress quiet(false);
  CalibrationTable& table = cache.calibration->second;
  CalibrationResult r;
  try {
    r = calibrate_on_table(table, scene, case_scene, plan.calibration, quiet);  // lent, not copied
  } catch (...) {
    if (table.table.coef.empty()) cache.calibration.reset();  // the model was not built: the table is gone
    throw;
  }
  // No constraint force requested: an empty field, never NaN.
  const std::string peak = plan.force.empty() ? std::string() : fmt::format("{:.10g}", r.peak_force_N);
  const auto peaks = plan.opt.peaks.empty() ? std::vector<double>()
                                            : calc_steady_cycle_peaks(case_scene, scene, cache.calibration->second,
                                                                      plan.calibration, r, plan.opt.peaks);
  return fmt::format("{:.10g},{:.10g},{:.10g},{},{:.10g},{}", r.load_value, r.mean_cadence_hz_reduced, r.mean_power_w,
                     peak, r.speed_fluctuation, peak_fields(peaks));
}

// A driven case's fields after its status: the reduced model over one revolution at the rate.
std::string driven_fields(const SweepPlan& plan, const models::Scene& case_scene, TableCache& cache) {
  const models::Scene scene = peak_table_scene(case_scene, plan.opt.peaks);
  const std::string key = table_key(scene);
  if (!cache.drive || cache.drive->first != key) {
    cache.drive.reset();
    ++cache.extracted;
    double grid = 0;  // a default grid refined quietly, as a calibrated case's
    const auto e = extract_resolving(engine::FullModel(scene), plan.calibration.grid_deg, plan.calibration.grid_given,
                                     reduced::Method::Kinetostatic, false, grid);
    // Only the columns its rows read: the model below fits its table every case.
    cache.drive.emplace(key, reduced::select_columns(e.samples, sweep_table_columns(case_scene, plan.opt.peaks)));
  }
  const auto model = reduced::make_reduced_model(cache.drive->second, scene, reduced::Interpolation::Fourier);
  const auto motion = revolution_motion(scene.initial.q, plan.opt.drive_cadence_hz);
  // With joint-output peaks: the rows' reactions and shaking from the table's reaction lines,
  // which calc_drive_reduced then drops (the scene's own forces stay, first as before).
  const DriveRecord r = peaks_need_joint_outputs(case_scene, plan.opt.peaks)
                            ? calc_drive_reduced(reduced_joint_output_scene(case_scene), model, motion)
                            : calc_drive_reduced(model, motion);
  const DriveStats st = calc_drive_stats(r);
  const std::string peak = st.force_peaks.empty() ? std::string() : fmt::format("{:.10g}", st.force_peaks[0]);
  const auto peaks = calc_column_peaks(
      drive_column_names(r, true), [&](size_t k) -> const std::vector<double>& { return drive_column(r, k); },
      plan.opt.peaks);
  return fmt::format("{:.10g},{:.10g},{:.10g},{:.10g},{:.10g},{},{}", st.rms, st.peak, st.mean, st.mean_power_W,
                     st.peak_power_W, peak, peak_fields(peaks));
}

// Case `index`'s row; `ok` false when it failed (its row then has status "error" and the message).
std::string case_row(const SweepPlan& plan, long index, TableCache& cache, bool& ok) {
  const SweepCase c = sweep_case(plan, index);
  const bool drive = plan.opt.drive_cadence_hz != 0;
  try {
    if (!cache.scenes) cache.scenes.emplace(plan.opt.scene);
    const auto scene = cache.scenes->load(c.overrides);
    const std::string fields = drive ? driven_fields(plan, scene, cache) : calibrated_fields(plan, scene, cache);
    ok = true;
    return fmt::format("{}{},ok,{}", index, c.params, fields);
  } catch (const std::exception& e) {
    ok = false;
    return fmt::format("{}{},error,{}{}", index, c.params, std::string(static_cast<size_t>(plan.result_fields), ','),
                       csv_field(e.what()));
  }
}

}  // namespace

SweepCase sweep_case(const SweepPlan& plan, long index) {
  SweepCase c;
  c.overrides = plan.fixed;
  long rest = index;
  const auto& axes = plan.opt.axes;
  for (auto it = axes.rbegin(); it != axes.rend(); ++it) {  // last axis varies fastest
    const double v = it->values[rest % it->values.size()];
    rest /= static_cast<long>(it->values.size());
    c.overrides.push_back({it->key, fmt::format("{:.17g}", v)});
    c.params = fmt::format(",{:.10g}", v) + c.params;
  }
  return c;
}

std::string run_sweep_case(const SweepPlan& plan, long index) {
  if (index < 0 || index >= plan.id.total)
    throw models::SceneError("", 0, "case", fmt::format("no case {} (the sweep has {})", index, plan.id.total));
  TableCache cache;
  bool ok = false;
  return case_row(plan, index, cache, ok);
}

SweepPlan plan_sweep(const SweepOptions& opt) {
  if (opt.shards < 1 || opt.shard < 0 || opt.shard >= opt.shards)
    throw models::SceneError("", 0, "--shard", "expected i/N with 0 ≤ i < N");
  SweepPlan plan;
  plan.opt = opt;
  for (const auto& s : opt.sets) plan.fixed.push_back(models::parse_override(s));
  const auto& fixed = plan.fixed;
  // The base scene must load (fails early, before any thread starts).
  models::SceneSource source(opt.scene);
  const models::Scene base = source.load(fixed);
  const bool drive = opt.drive_cadence_hz != 0;
  CalibrationOptions copt;
  if (drive) {
    // A drive sweep calibrates nothing: the cases run at the rate given.
    if (opt.cadence_hz > 0 || opt.power_w > 0 || !opt.load.empty())
      throw models::SceneError(base.source_file, 0, "--drive-cadence-hz",
                               "a drive sweep does not calibrate: give --drive-cadence-hz without --cadence-hz, "
                               "--power-w and --load");
    if (!std::isfinite(opt.drive_cadence_hz))  // its range: the command line's (validate/cli)
      throw models::SceneError(base.source_file, 0, "--drive-cadence-hz", "must be a finite, non-zero rate");
    if (base.find_joint(base.independent)->type != models::JointType::Revolute)
      throw models::SceneError(base.source_file, 0, "--drive-cadence-hz",
                               "a constant rate needs a revolute independent coordinate");
    copt.grid_deg = opt.grid_given ? opt.grid_deg : base.validation.calibrate_grid_deg;
    copt.grid_given = opt.grid_given || base.validation.calibrate_grid_given;
    copt.cadence_hz = 0.0;
  } else {
    // The same options as `rdyn calibrate`: the command line, else the scene's validation.calibrate.
    copt = calibration_options_of(base, opt.cadence_hz, opt.power_w, opt.load);
    if (opt.grid_given) {  // else the scene's grid_deg, or 10° refined where it does not resolve m1
      copt.grid_deg = opt.grid_deg;
      copt.grid_given = true;
    }
    copt.full_max_s = 0.0;  // reduced model only: this is what sweeps are for
    if (!(copt.cadence_hz > 0))
      throw models::SceneError(base.source_file, 0, "--cadence-hz",
                               "give it, or a validation.calibrate block in the scene");
    check_calibratable(base, copt);  // a scene that cannot be calibrated fails here, not in every case
  }
  // The peak columns: each a column of the base scene's reduced run, its reactions ones the
  // reduced model gives (with_reaction_requests' TableError otherwise), before any case runs.
  check_peak_columns(base, opt.peaks, drive);
  peak_table_scene(base, opt.peaks);
  // Every axis at both ends of its range on the base scene: unknown keys and values out of
  // range fail here, before any thread starts. Ends of two tables: the axis changes the mechanism.
  for (const auto& a : opt.axes) {
    std::vector<std::string> keys;
    for (double v : {a.values.front(), a.values.back()}) {
      std::vector<models::Override> o = fixed;
      o.push_back({a.key, fmt::format("{:.17g}", v)});
      keys.push_back(table_key(source.load(o)));
    }
    plan.changes_mechanism.push_back(keys[0] != keys[1]);
  }

  for (size_t i = 0; i < opt.axes.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (opt.axes[i].key == opt.axes[j].key)
        throw models::SceneError("", 0, "--vary " + opt.axes[i].key, "the key is varied twice; give it once");
  constexpr long kMaxCases = 1000000;
  long total = 1;
  for (const auto& a : opt.axes) {
    total *= static_cast<long>(a.values.size());
    if (total > kMaxCases)
      throw models::SceneError("", 0, "--vary", fmt::format("more than {} cases in all", kMaxCases));
  }
  plan.calibration = copt;
  plan.force = base.outputs.constraint_forces.empty() ? "" : base.outputs.constraint_forces[0].name;
  plan.header = "case";
  for (const auto& a : opt.axes) plan.header += "," + csv_field(a.key);
  const std::string force_column = plan.force.empty() ? "constraint" : plan.force;
  if (drive)
    plan.header += fmt::format(",status,drive_rms_Nm,drive_peak_Nm,drive_mean_Nm,mean_power_w,peak_power_w,peak_{}_force_N",
                               force_column);
  else
    plan.header += fmt::format(",status,{},mean_cadence_hz,mean_power_w,peak_{}_force_N,speed_fluctuation",
                               load_value_column(base, copt), force_column);
  for (const auto& p : opt.peaks) plan.header += "," + csv_field("peak_" + p);
  plan.header += ",error";
  plan.result_fields = (drive ? 6 : 5) + static_cast<int>(opt.peaks.size());
  plan.id.total = total;
  plan.id.scene_hex = models::scene_hash_hex(models::scene_hash(base));
  plan.id.sweep_hex = models::scene_hash_hex(models::fnv1a64(sweep_defining_text(base, plan)));
  plan.range = shard_range(total, opt.shard, opt.shards);
  return plan;
}

SweepResult run_sweep(const SweepOptions& opt) { return run_sweep(plan_sweep(opt), nullptr); }

SweepResult run_sweep(const SweepPlan& plan, StderrProgress* progress) {
  const SweepOptions& opt = plan.opt;
  const long first = plan.range.first;
  const long n = plan.range.end - plan.range.first;
  const auto t0 = std::chrono::steady_clock::now();
  const int threads = static_cast<int>(std::clamp<long>(
      opt.threads > 0 ? opt.threads : static_cast<long>(std::thread::hardware_concurrency()), 1, std::max(1L, n)));
  const RunOrder order = run_order(plan, threads);
  const long chunks = static_cast<long>(order.chunks.size()) - 1;

  std::vector<std::string> rows(n);
  std::atomic<long> next{0}, done{0}, failed{0}, tables{0}, walks{0};
  auto work = [&] {
    TableCache cache;
    for (long c; (c = next.fetch_add(1)) < chunks;) {
      for (long k = order.chunks[c]; k < order.chunks[c + 1]; ++k) {
        const long index = order.cases[k];
        bool ok = false;
        rows[index - first] = case_row(plan, index, cache, ok);
        if (!ok) ++failed;
        const long d = ++done;
        if (progress) progress->done(d);
      }
    }
    tables += cache.extracted;
    walks += cache.walks;
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(work);
  for (auto& t : pool) t.join();

  SweepResult r;
  r.csv = sweep_csv(plan.id, plan.range, plan.header, rows);
  r.cases = n;
  r.failed = failed.load();
  r.threads = threads;
  r.tables = tables.load();
  r.walks = walks.load();
  r.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace rdyn::validate
