#include "validate/analysis/optimize.hpp"
#include "validate/analysis/optimize_design.hpp"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "reduced/profile_columns.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/confirm_full.hpp"

namespace rdyn::validate {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kTwoPi = 2 * M_PI;
// Sampled constraints: τ(θ_i) ≥ 0 at 5° spacing (a series of ≤ 12 harmonics has no dip
// narrower than ~15° that falls between samples by more than a few percent of its depth), and
// the bound on |value·τ| at 1° spacing.
constexpr int kNonnegativeSamples = 72;
constexpr int kBoundSamples = 360;
// A failed evaluation (no steady cycle, no amplitude holding F): a large finite objective,
// 10× the constant strategy's, and a violated bound, never NaN into NLopt.
constexpr double kPenalty = 10.0;
// Coefficients searched within ±kCoefficientBound of a unit mean (a0 = 1 of the first shape).
constexpr double kCoefficientBound = 4.0;
constexpr double kInitialStep = 0.2;

struct Evaluation {
  std::vector<double> x;
  bool ok = false;
  double objective = 0.0;          // peak or p-norm [N]
  double peak = 0.0;               // [N]
  std::vector<double> max_tau;     // per group: max |τ(θ)| over the samples
  CalibrationResult cal;
};

// The search's inputs (read only: every candidate builds its own model from them) and its
// per-run state (the last evaluation, the counters).
struct Workspace {
  const models::Scene* scene = nullptr;  // with the added torques, design loads profiled
  const Design* design = nullptr;
  CalibrationOptions copt;
  const reduced::Samples* samples = nullptr;    // the one extraction
  const reduced::ReducedModel* base = nullptr;  // built from it at unit load; each shape refits a copy
  reduced::Interpolation interp = reduced::Interpolation::Fourier;
  int force = 0;
  bool pnorm = false;
  double p = 8.0;
  double objective_scale = 1.0;  // the constant strategy's objective
  Evaluation last;
  int evaluations = 0, failures = 0;
  Progress* progress = nullptr;
  int max_evaluations = 0;
};

// One shape's table: the extraction's samples with the tau columns of `shaped` (its design loads
// profiled; load values as they are) and a copy of the base model with those columns refit
// (reduced/profile_columns.hpp: never re-extracted). A fresh copy per shape, so no shape's
// columns, load values or resistance coefficient are left behind for the next.
struct ShapeModel {
  reduced::Samples samples;
  reduced::ReducedModel model;
};
ShapeModel calc_shape_model(const Workspace& w, const models::Scene& shaped) {
  ShapeModel sm{reduced::with_profile_columns(*w.samples, shaped), *w.base};
  reduced::refit_profile_columns(sm.model, sm.samples, w.interp);
  return sm;
}

// The scene of a calibrated shape: the design loads profiled at x, each at the calibrated
// amplitude (its sign in the scene kept), the resistance coefficient its own calibration found
// (power mode), a point of its steady cycle as initial state. A strategy's reduced curves, its
// p-norm and its full-model run are all built from this one scene.
models::Scene calibrated_scene(const models::Scene& scene, const Design& d, const double* x,
                               const CalibrationResult& cal) {
  models::Scene sx = shaped_scene(scene, d, x);
  for (const auto& dl : d.loads) {
    auto& t = sx.joint_torques[dl.torque];
    t.value = (scene.joint_torques[dl.torque].value < 0 ? -1.0 : 1.0) * std::abs(cal.load_value);
  }
  if (std::isfinite(cal.resistance_coefficient)) sx.resistances[0].coefficient = cal.resistance_coefficient;
  sx.initial.q = cal.steady_q;
  sx.initial.qdot = cal.steady_qdot;
  return sx;
}

// The reduced model of a calibrated scene on its shape's table (its own loads, the table shared).
reduced::ReducedModel calc_calibrated_model(const ShapeModel& sm, const models::Scene& calibrated) {
  return reduced::make_reduced_model(sm.samples, calibrated, sm.model.table);
}

// (mean |F|^p)^(1/p) over one steady cycle, sampled at 720 equal time steps.
double calc_pnorm(const reduced::ReducedModel& m, double q, double qdot, double period, double tol, int k, double p) {
  reduced::ReducedOptions ro;
  ro.duration_s = period;
  ro.output_interval_s = period / 720;
  ro.tolerance = tol;
  const auto ts = reduced::simulate_reduced(m, q, qdot, ro);
  double peak = 0.0;
  for (size_t i = 0; i + 1 < ts.t.size(); ++i) peak = std::max(peak, std::abs(ts.forces[k][i]));
  if (!(peak > 0)) return 0.0;
  double sum = 0.0;
  const size_t n = ts.t.size() - 1;
  for (size_t i = 0; i < n; ++i) sum += std::pow(std::abs(ts.forces[k][i]) / peak, p);  // scaled: no overflow
  return peak * std::pow(sum / n, 1.0 / p);
}

const Evaluation& evaluate(Workspace& w, const double* x) {
  if (w.last.x.size() == static_cast<size_t>(w.design->n) && std::equal(w.last.x.begin(), w.last.x.end(), x))
    return w.last;
  Evaluation e;
  e.x.assign(x, x + w.design->n);
  const Design& d = *w.design;
  for (int g = 0; g < static_cast<int>(d.groups.size()); ++g) {
    const Series s = group_series(d, g, x);
    double mx = 0.0;
    for (int i = 0; i < kBoundSamples; ++i) mx = std::max(mx, std::abs(eval_series(s, kTwoPi * i / kBoundSamples)));
    e.max_tau.push_back(mx);
  }
  ++w.evaluations;
  try {
    const auto sx_unit = with_unit_load(shaped_scene(*w.scene, d, x), w.copt);
    const ShapeModel sm = calc_shape_model(w, sx_unit);
    Progress silent(false);
    e.cal = calibrate_reduced(sm.model, sx_unit, w.copt, silent);
    e.peak = e.cal.peak_forces_N.at(w.force);
    e.objective = w.pnorm ? calc_pnorm(calc_calibrated_model(sm, calibrated_scene(*w.scene, d, x, e.cal)),
                                       e.cal.steady_q, e.cal.steady_qdot, 1.0 / e.cal.mean_cadence_hz_reduced,
                                       w.copt.tolerance, w.force, w.p)
                          : e.peak;
    e.ok = std::isfinite(e.objective) && std::isfinite(e.cal.load_value);
  } catch (const models::NumericalError&) {
    e.ok = false;  // no cycle or no amplitude holding F: a penalty, not an error
  } catch (const models::SceneError&) {
    e.ok = false;  // a shape doing no net work (the amplitude cannot hold F)
  }
  if (!e.ok) ++w.failures;
  if (w.progress) w.progress->count("optimize: evaluations", w.evaluations, w.max_evaluations);
  w.last = std::move(e);
  return w.last;
}

// Lifts every nonnegative group's series whose true minimum m is below 0 to τ ≥ 0 at every
// angle: a free a0 rises by δ = −m; with a0 ≡ 1 (the first group) the series becomes
// (τ + δ)/(1 + δ), its harmonics divided by 1 + δ. Returns the largest δ (0: none needed).
double repair_nonnegative(const Design& d, std::vector<double>& x) {
  double largest = 0.0;
  for (int g = 0; g < static_cast<int>(d.groups.size()); ++g) {
    if (!d.groups[g].nonnegative) continue;
    const double m = series_minimum(group_series(d, g, x.data()));
    if (!(m < 0)) continue;
    const double delta = -m * (1 + 1e-12) + 1e-15;  // strictly lifted past rounding
    largest = std::max(largest, delta);
    const int first = d.groups[g].offset;
    if (d.groups[g].fixed_a0) {
      for (int k = 0; k < 2 * d.H; ++k) x[first + k] /= 1 + delta;
    } else {
      x[first] += delta;
    }
  }
  return largest;
}

double objective_fn(unsigned n, const double* x, double* grad, void* data) {
  (void)n;
  (void)grad;  // derivative-free (COBYLA)
  auto& w = *static_cast<Workspace*>(data);
  const auto& e = evaluate(w, x);
  return e.ok ? e.objective / w.objective_scale : kPenalty;
}

// Inequality constraints c(x) ≤ 0: −τ_g(θ_i) for nonnegative groups, then per group
// (A·max|τ_g| − bound)/bound.
void constraints_fn(unsigned m, double* result, unsigned n, const double* x, double* grad, void* data) {
  (void)n;
  (void)grad;
  auto& w = *static_cast<Workspace*>(data);
  const Design& d = *w.design;
  unsigned i = 0;
  for (int g = 0; g < static_cast<int>(d.groups.size()); ++g) {
    if (!d.groups[g].nonnegative) continue;
    const Series s = group_series(d, g, x);
    for (int k = 0; k < kNonnegativeSamples; ++k) result[i++] = -eval_series(s, kTwoPi * k / kNonnegativeSamples);
    result[i++] = -series_minimum(s);  // between the samples too (the samples steer COBYLA's linear model)
  }
  const auto& e = evaluate(w, x);
  for (int g = 0; g < static_cast<int>(d.groups.size()); ++g)
    result[i++] = e.ok ? (std::abs(e.cal.load_value) * e.max_tau[g] - d.groups[g].bound) / d.groups[g].bound : 1.0;
  (void)m;
}

// A strategy's curves over the independent coordinate's angle on the reduced model of its own
// calibrated scene `sx`: the applied design loads (value·τ·gate) at 0°, 1°, … 359°, and the
// force over one steady period from the steady point. That period must close the cycle (q
// advances by the table's period, q̇ returns): a model at other load values or another resistance
// coefficient than the calibration's would not, and its curve would not be the record's.
void calc_reduced_curves(const reduced::ReducedModel& m, const models::Scene& sx, const Design& d, int force,
                         double period_s, const std::string& label, StrategyCurves& c) {
  reduced::ReducedOptions ro;
  ro.duration_s = period_s;
  ro.output_interval_s = period_s / 1440;
  ro.tolerance = 1e-10;
  const auto cyc = reduced::simulate_reduced(m, sx.initial.q, sx.initial.qdot, ro);
  const double turn = std::abs(cyc.q.back() - cyc.q.front()), speed = std::abs(sx.initial.qdot);
  const double P = m.table.period;  // 2π: optimize's coordinate turns fully
  if (!(std::abs(turn - P) <= 1e-6 * P && std::abs(std::abs(cyc.qdot.back()) - speed) <= 1e-6 * speed))
    throw models::NumericalError(fmt::format(
        "optimize: the {} strategy's reduced model does not repeat its steady cycle (one period {:.6g} s turns q by "
        "{:.6g} rad, q̇ {:.6g} → {:.6g} rad/s): its curves would not be its summary's",
        label, period_s, turn, sx.initial.qdot, cyc.qdot.back()));
  c.torque_Nm.assign(d.loads.size(), std::vector<double>(360));
  for (int a = 0; a < 360; ++a) {
    const double q = a * M_PI / 180;
    c.angle_deg.push_back(a);
    for (size_t l = 0; l < d.loads.size(); ++l) {
      const auto& mt = m.torques[d.loads[l].torque];
      const bool on = mt.gate < 0 || reduced::calc_switching(m, mt.gate, q, sx.initial.qdot) > 0;
      // The tau column is τ(θ_of(q)) whichever joint the shape reads.
      c.torque_Nm[l][a] = on ? mt.value * m.table.eval(mt.c_tau, q) : 0.0;
    }
  }
  // Force over the angle: the cycle's rows by angle.
  std::vector<std::pair<double, double>> pts;
  for (size_t i = 0; i < cyc.t.size(); ++i) pts.push_back({cyc.q[i], cyc.forces[force][i]});
  c.force_reduced_N = calc_by_angle(std::move(pts));
}

// One strategy's record, computed once: the search's numbers for its shape xs (evaluation e),
// its coefficients, and its curves and full-model run, both from the one calibrated scene
// (returned beside the record).
std::pair<StrategyResult, models::Scene> calc_strategy(const Workspace& w, const Design& d,
                                                       const std::vector<double>& xs, const Evaluation& e,
                                                       const OptimizeOptions& opt, const std::string& label) {
  StrategyResult sr;
  sr.amplitude = std::abs(e.cal.load_value);
  sr.resistance_coefficient = e.cal.resistance_coefficient;
  sr.peak_reduced_N = e.peak;
  sr.objective_reduced = e.objective;
  sr.cadence_reduced_hz = e.cal.mean_cadence_hz_reduced;
  sr.mean_power_w = e.cal.mean_power_w;
  sr.steady_q = e.cal.steady_q;
  sr.steady_qdot = e.cal.steady_qdot;
  const models::Scene sx = calibrated_scene(*w.scene, d, xs.data(), e.cal);
  for (const auto& dl : d.loads) {
    const auto& t = sx.joint_torques[dl.torque];
    sr.a0.push_back(t.profile->a0);
    sr.a.push_back(t.profile->a);
    sr.b.push_back(t.profile->b);
    double mx = 0;
    for (int i = 0; i < kBoundSamples; ++i)
      mx = std::max(mx, std::abs(models::calc_joint_torque(t, kTwoPi * i / kBoundSamples)));
    sr.max_torque_Nm = std::max(sr.max_torque_Nm, mx);
  }
  // Reduced: the shape's table (as its calibration had it) with the calibrated scene's loads.
  const ShapeModel sm = calc_shape_model(w, with_unit_load(sx, w.copt));
  calc_reduced_curves(calc_calibrated_model(sm, sx), sx, d, w.force, 1.0 / sr.cadence_reduced_hz, label, sr.curves);
  // Full: mean cadence over whole revolutions after full_skip_s, the force's peak and last revolution.
  FullConfirmOptions fc;
  fc.duration_s = opt.full_duration_s;
  fc.skip_s = opt.full_skip_s;
  fc.force = w.force;
  const FullConfirmation fw = confirm_full(sx, fc);
  sr.cadence_full_hz = fw.cadence_hz;
  sr.peak_full_N = fw.peak_force_N;
  sr.curves.force_full_N = fw.force_1deg;
  return {sr, sx};
}

}  // namespace

models::Scene scene_with_added_torques(const models::Scene& scene, const OptimizeOptions& opt) {
  models::Scene s = scene;
  for (const auto& j : opt.add_torques) {
    auto fail = [&](const std::string& msg) { throw models::SceneError(scene.source_file, 0, "--add-torque", msg); };
    if (!models::is_valid_name(j)) fail(models::invalid_name_message(j));
    const auto* joint = s.find_joint(j);
    if (!joint) fail("unknown joint '" + j + "'");
    if (joint->type != models::JointType::Revolute) fail("'" + j + "' is not a revolute joint");
    const std::string name = "torque_" + j;
    if (std::count(opt.add_torques.begin(), opt.add_torques.end(), j) > 1) fail("joint '" + j + "' is given twice");
    for (const auto& t : s.joint_torques)
      if (t.name == name) fail("the scene already has a joint torque named '" + name + "'");
    s.joint_torques.push_back({name, j, 1.0, std::nullopt, std::nullopt});
  }
  return s;
}

void check_optimize_options(const models::Scene& scene, const OptimizeOptions& opt) {
  auto fail = [&](const std::string& field, const std::string& msg) {
    throw models::SceneError(scene.source_file, scene.line_of(field), scene.field_of(field), msg);
  };
  if (opt.harmonics != 0 && (opt.harmonics < 1 || opt.harmonics > models::kMaxOptimizeHarmonics))
    fail("--harmonics", fmt::format("must be a whole number in [1, {}] (got {})", models::kMaxOptimizeHarmonics,
                                    opt.harmonics));
  if (!opt.objective.empty() && opt.objective != "peak" && opt.objective != "pnorm")
    fail("--objective", "expected peak or pnorm");
  if (opt.p != 0 && !(opt.p >= 2 && opt.p <= 64)) fail("--p", fmt::format("must be in [2, 64] (got {:g})", opt.p));
  if (opt.max_load != 0 && !(opt.max_load > 0 && opt.max_load <= models::limits::kMaxForce))
    fail("--max-load", fmt::format("must be in (0, {:g}] N·m or N (got {:g})", models::limits::kMaxForce, opt.max_load));
  if (!(opt.add_torque_max > 0 && opt.add_torque_max <= models::limits::kMaxForce))
    fail("--add-torque-max", fmt::format("must be in (0, {:g}] N·m (got {:g})", models::limits::kMaxForce,
                                         opt.add_torque_max));
  if (opt.max_evaluations < 1 || opt.max_evaluations > kMaxOptimizeEvaluations)
    fail("--max-evaluations", fmt::format("must be in [1, {}] (got {})", kMaxOptimizeEvaluations, opt.max_evaluations));
  if (!(opt.rel_tolerance >= 1e-12 && opt.rel_tolerance <= 0.1))
    fail("--rel-tolerance", fmt::format("must be in [1e-12, 0.1] (got {:g})", opt.rel_tolerance));
  if (!(opt.full_duration_s >= kMinOptimizeFullDuration_s && opt.full_duration_s <= kMaxOptimizeFullDuration_s))
    fail("--full-duration", fmt::format("must be in [{:g}, {:g}] s (got {:g})", kMinOptimizeFullDuration_s,
                                        kMaxOptimizeFullDuration_s, opt.full_duration_s));
  if (!(opt.full_skip_s >= 0 && opt.full_skip_s <= 0.5 * opt.full_duration_s))
    fail("--full-skip", fmt::format("must be in [0, half the full duration] s (got {:g})", opt.full_skip_s));
  const auto& cf = scene.outputs.constraint_forces;
  const std::string force = !opt.force_name.empty() ? opt.force_name
                            : scene.optimize && !scene.optimize->force.empty() ? scene.optimize->force
                                                                               : std::string();
  if (cf.empty()) fail("outputs.constraint_forces", "optimize minimises a constraint force: request one");
  // One amplitude scales the design loads (every joint torque) to hold the cadence, every other
  // load as given. A motor or a point force would drive beside them, neither shaped nor scaled:
  // with a motor as the real drive (slider-crank) the design load is the piston's load, which
  // does no net work per revolution; with muscles calibrated for the operating point
  // (bicycle-muscle) an added torque has nothing left to do. Refused before any work.
  std::string designed;
  for (const auto& t : scene.joint_torques) designed += (designed.empty() ? "'" : ", '") + t.name + "'";
  if (designed.empty()) designed = "none in this scene";
  auto refuse_drive = [&](const std::string& kind, const std::string& name, const std::string& joint) {
    throw models::SceneError(
        scene.source_file, scene.line_of("loads." + name), "loads." + name,
        fmt::format("{} '{}' drives the mechanism but is not a design load: optimize shapes the joint torques ({}) "
                    "and calibrates one amplitude for them to hold the cadence, every other load as given, so the "
                    "drive must be joint torques alone; give the drive as a joint_torque{} and remove the {}",
                    kind, name, designed, joint.empty() ? "" : " on joint '" + joint + "'", kind));
  };
  // A motor or a point force is named at its own line before the missing joint torques: a
  // motor-driven scene was refused at `loads` without a line.
  for (const auto& mo : scene.motors) refuse_drive("motor", mo.name, mo.joint);
  for (const auto& pf : scene.point_forces) refuse_drive("point force", pf.name, "");
  if (scene.joint_torques.empty())
    fail("loads", "optimize shapes joint torques and the scene has none: add a joint_torque, or one with --add-torque "
                  "JOINT");
  if (!force.empty() &&
      std::none_of(cf.begin(), cf.end(), [&](const models::ConstraintForceRequest& c) { return c.name == force; }))
    fail(opt.force_name.empty() ? "optimize.force" : "--force-name",
         "no requested constraint force named '" + force + "' (outputs.constraint_forces)");
  if (!scene.find_joint(scene.independent) || scene.find_joint(scene.independent)->type != models::JointType::Revolute)
    fail("independent", "optimize shapes loads over a revolute independent coordinate that turns fully");
}

namespace {

// Stage 1: what the result describes before any work: the objective, the design loads and their
// shifts and groups, the force minimised (`force`: its index among the constraint forces).
OptimizeResult describe_problem(const models::Scene& scene, const models::OptimizeSpec& spec, const Design& design,
                                const OptimizeOptions& opt, int& force) {
  OptimizeResult r;
  r.scene = scene.name;
  r.objective = !opt.objective.empty() ? opt.objective : spec.objective;
  r.p = opt.p > 0 ? opt.p : spec.p;
  r.harmonics = design.H;
  r.profile_of = design.of;
  r.independent = scene.independent;
  r.full_duration_s = opt.full_duration_s;
  r.cadence_hz = opt.cadence_hz;
  r.power_w = opt.power_w;
  r.force_name = !opt.force_name.empty() ? opt.force_name
                 : !spec.force.empty()   ? spec.force
                                         : scene.outputs.constraint_forces[0].name;
  force = 0;
  while (scene.outputs.constraint_forces[force].name != r.force_name) ++force;
  for (const auto& dl : design.loads) {
    r.design_loads.push_back(scene.joint_torques[dl.torque].name);
    r.shift_deg.push_back(dl.shift * 180 / M_PI);
  }
  for (size_t i = 0; i < design.loads.size(); ++i) {
    std::string same;
    for (size_t j = 0; j < i; ++j)
      if (design.loads[j].group == design.loads[i].group) {
        same = r.design_loads[j];
        break;
      }
    r.same_as.push_back(same);
  }
  for (const auto& j : opt.add_torques) r.added_loads.push_back("torque_" + j);
  return r;
}

// Calibration as `rdyn calibrate` does it, every joint torque (the design loads) together.
CalibrationOptions calibration_options_for(const OptimizeOptions& opt) {
  CalibrationOptions copt;
  copt.cadence_hz = opt.cadence_hz;
  copt.power_w = opt.power_w;
  copt.load_field = "optimize.loads";
  copt.grid_deg = opt.grid_deg;
  copt.interpolation = opt.interpolation;
  copt.full_max_s = 0;
  return copt;
}

// Stage 2: the one extraction; the shape's angle is q itself or the joint-position column of `of`.
reduced::Samples extract_for_design(const models::Scene& s0, const Design& design, const models::Scene& scene,
                                    const OptimizeOptions& opt, double& grid_deg_used) {
  models::Scene s_extract = s0;
  if (design.of != scene.independent &&
      std::find(s_extract.outputs.joints.begin(), s_extract.outputs.joints.end(), design.of) ==
          s_extract.outputs.joints.end())
    s_extract.outputs.joints.push_back(design.of);
  return extract_resolving(s_extract, opt.grid_deg, opt.grid_given, reduced::Method::Kinetostatic, grid_deg_used)
      .samples;
}

// The design with every group's bound set: the documented default is 5× the constant strategy's
// value.
Design bounded_design(const Design& design, double max_load) {
  Design bounded = design;
  for (auto& g : bounded.groups)
    if (!(g.bound > 0)) g.bound = max_load;
  return bounded;
}

// Stage 3: COBYLA (derivative-free, handles the sampled inequality constraints directly) from
// x0; returns the point NLopt ends at and records the stop reason and counts in r.
std::vector<double> search(Workspace& w, const Design& bounded, const std::vector<double>& x0,
                           const OptimizeOptions& opt, Progress& progress, OptimizeResult& r) {
  const auto t_search = Clock::now();
  const unsigned n = static_cast<unsigned>(bounded.n);
  nlopt_opt o = nlopt_create(NLOPT_LN_COBYLA, n);
  std::unique_ptr<nlopt_opt_s, decltype(&nlopt_destroy)> guard(o, nlopt_destroy);
  std::vector<double> lb(n, -kCoefficientBound), ub(n, kCoefficientBound);
  for (const auto& g : bounded.groups)
    if (!g.fixed_a0 && g.nonnegative) lb[g.offset] = 0.0;
  nlopt_set_lower_bounds(o, lb.data());
  nlopt_set_upper_bounds(o, ub.data());
  nlopt_set_min_objective(o, objective_fn, &w);
  unsigned m = 0;
  for (const auto& g : bounded.groups) m += (g.nonnegative ? kNonnegativeSamples + 1 : 0) + 1;
  std::vector<double> ctol(m, 1e-9);
  nlopt_add_inequality_mconstraint(o, m, constraints_fn, &w, ctol.data());
  nlopt_set_xtol_rel(o, opt.rel_tolerance);
  nlopt_set_ftol_rel(o, opt.rel_tolerance);
  nlopt_set_maxeval(o, opt.max_evaluations);
  nlopt_set_initial_step1(o, kInitialStep);
  std::vector<double> x = x0;
  double fmin = 0.0;
  w.evaluations = 0;
  w.progress = &progress;
  const nlopt_result res = n > 0 ? nlopt_optimize(o, x.data(), &fmin) : NLOPT_SUCCESS;
  r.stop_reason = res == NLOPT_MAXEVAL_REACHED    ? "max_evaluations"
                  : res == NLOPT_XTOL_REACHED     ? "xtol"
                  : res == NLOPT_FTOL_REACHED     ? "ftol"
                  : res == NLOPT_ROUNDOFF_LIMITED ? "roundoff"
                  : res > 0                       ? "converged"
                                                  : fmt::format("nlopt error {}", static_cast<int>(res));
  r.evaluations = w.evaluations;
  r.failed_evaluations = w.failures;
  r.optimise_wall_s = std::chrono::duration<double>(Clock::now() - t_search).count();
  return x;
}

// Stage 4: the search's end point made exactly nonnegative where asked and re-evaluated; kept
// only when it is feasible and better than the constant strategy (x, best ← x0, e0 otherwise).
// COBYLA meets its constraints only to its own tolerance (the bicycle's optimum dipped to
// −1.3e-4 of the mean): each nonnegative shape is lifted to τ ≥ 0 at every angle, then recalibrated.
Evaluation keep_feasible_optimum(Workspace& w, const Design& bounded, std::vector<double>& x,
                                 const std::vector<double>& x0, const Evaluation& e0, OptimizeResult& r) {
  r.nonnegative_repair = repair_nonnegative(bounded, x);
  Evaluation best = evaluate(w, x.data());
  bool feasible = best.ok;
  for (size_t g = 0; g < bounded.groups.size() && feasible; ++g) {
    feasible = std::abs(best.cal.load_value) * best.max_tau[g] <= bounded.groups[g].bound * (1 + 1e-6);
    // τ ≥ 0 at every angle (after the repair: to rounding).
    if (bounded.groups[g].nonnegative) feasible = feasible && series_minimum(group_series(bounded, g, x.data())) >= -1e-12;
  }
  if (!feasible || !(best.objective < e0.objective)) {
    x = x0;
    best = e0;
  }
  return best;
}

// Stage 5: both strategies on the full model, the optimised scene, and the comparisons.
void finish_strategies(const Workspace& w, const Design& bounded, const std::vector<double>& x0, const Evaluation& e0,
                       const std::vector<double>& x, const Evaluation& best, const models::Scene& scene,
                       const OptimizeOptions& opt, Progress& progress, OptimizeResult& r) {
  progress.note("optimize: full model, constant strategy");
  auto [c0, scene0] = calc_strategy(w, bounded, x0, e0, opt, "constant");
  r.constant_scene = std::move(scene0);
  progress.note("optimize: full model, optimised strategy");
  auto [c1, scene1] = calc_strategy(w, bounded, x, best, opt, "optimised");
  r.constant = c0;
  r.optimised = c1;
  // The optimised scene's coefficient (each strategy dissipates P on its own steady cycle).
  if (std::isfinite(r.resistance_coefficient)) r.resistance_coefficient = best.cal.resistance_coefficient;
  scene1.optimize.reset();
  scene1.description = fmt::format("{} Optimised by rdyn optimize: {} shaped over {} to minimise the peak {} force at {:g} Hz.",
                                   scene.description.substr(0, 3000), fmt::join(r.design_loads, ", "), bounded.of,
                                   r.force_name, opt.cadence_hz);
  r.optimised_scene = scene1;
  // The published values beside a calibration (validation.compare) describe the scene's own
  // strategy, not the optimised one: a validate of the optimised scene must not compare them.
  r.optimised_scene.validation.compare.clear();
  r.reduction_reduced = 1 - c1.peak_reduced_N / c0.peak_reduced_N;
  r.reduction_full = 1 - c1.peak_full_N / c0.peak_full_N;
  r.agreement = std::abs(c1.peak_full_N - c1.peak_reduced_N) / c1.peak_full_N;
  auto cadence_ok = [&](double f) { return std::isfinite(f) && std::abs(f - opt.cadence_hz) <= kFullCadenceTolerance * opt.cadence_hz; };
  r.full_cadence_ok = cadence_ok(c0.cadence_full_hz) && cadence_ok(c1.cadence_full_hz);
  r.full_better = std::isfinite(c1.peak_full_N) && c1.peak_full_N < c0.peak_full_N;
}

}  // namespace

OptimizeResult optimize(const models::Scene& scene_in, const OptimizeOptions& opt, Progress& progress) {
  const auto start = Clock::now();
  const models::Scene scene = scene_with_added_torques(scene_in, opt);
  check_optimize_options(scene, opt);
  const models::OptimizeSpec spec = scene.optimize.value_or(models::OptimizeSpec{});
  const Design design = resolve_design(scene, spec, opt);
  int force = 0;
  OptimizeResult r = describe_problem(scene, spec, design, opt, force);
  const CalibrationOptions copt = calibration_options_for(opt);
  std::vector<double> x0(design.n, 0.0);
  for (const auto& g : design.groups)
    if (!g.fixed_a0) x0[g.offset] = g.a0_start;
  const models::Scene s0 = shaped_scene(scene, design, x0.data());  // the constant strategy, profiled
  check_calibratable(s0, copt);
  r.resistance_coefficient = calc_resistance_coefficient(s0, copt);

  progress.note("optimize: extracting the reduced table");
  Workspace w;
  w.design = &design;
  w.copt = copt;
  w.interp = reduced::parse_interpolation(opt.interpolation);
  const reduced::Samples samples = extract_for_design(s0, design, scene, opt, r.grid_deg);
  w.copt.grid_deg = r.grid_deg;
  const reduced::ReducedModel base = reduced::make_reduced_model(samples, with_unit_load(s0, copt), w.interp);
  w.samples = &samples;
  w.base = &base;
  w.scene = &scene;
  w.force = force;
  w.pnorm = r.objective == "pnorm";
  w.p = r.p;
  w.max_evaluations = opt.max_evaluations + 1;

  // The constant strategy: its refusals are the scene's (exit 2), its failure exit 1.
  {
    Progress silent(false);
    (void)calibrate_reduced(base, with_unit_load(s0, copt), copt, silent);
  }
  const Evaluation e0 = evaluate(w, x0.data());
  if (!e0.ok) throw models::NumericalError("optimize: the constant strategy has no steady cycle holding the cadence");
  w.objective_scale = e0.objective > 0 ? e0.objective : 1.0;
  r.max_load = design.groups[0].bound > 0 ? design.groups[0].bound : 5.0 * std::abs(e0.cal.load_value);
  const Design bounded = bounded_design(design, r.max_load);
  w.design = &bounded;
  w.last = Evaluation{};

  progress.note("optimize: searching");
  std::vector<double> x = search(w, bounded, x0, opt, progress, r);
  const Evaluation best = keep_feasible_optimum(w, bounded, x, x0, e0, r);
  finish_strategies(w, bounded, x0, e0, x, best, scene, opt, progress, r);
  r.wall_time_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

std::string optimize_failure_message(const OptimizeResult& r) {
  std::string m;
  auto reached = fmt::format(
      "reached: peak {} {:.6g} N (constant) → {:.6g} N (optimised) on the full model, {:.6g} → {:.6g} N reduced; "
      "full-model cadence {:.6g} Hz (constant), {:.6g} Hz (optimised), target {:g} Hz",
      r.force_name, r.constant.peak_full_N, r.optimised.peak_full_N, r.constant.peak_reduced_N,
      r.optimised.peak_reduced_N, r.constant.cadence_full_hz, r.optimised.cadence_full_hz, r.cadence_hz);
  if (!r.full_cadence_ok)
    m = fmt::format("optimize not confirmed: the full model misses the cadence by more than 1 % ({})", reached);
  else if (!r.full_better)
    m = fmt::format("optimize not confirmed: the optimised strategy is not better on the full model ({})", reached);
  return m;
}

}  // namespace rdyn::validate
