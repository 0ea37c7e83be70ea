#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/calibration_load.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "reduced/steady_cycle.hpp"
#include "validate/analysis/operating_point.hpp"
#include "validate/analysis/revolution_work.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/confirm_full.hpp"

namespace rdyn::validate {

namespace {

// Acceptance of a calibration (relative cadence error). Reduced: the steady cycle is solved to
// 1e-12 and the load value to 1e-10, so any genuine root meets 1e-6 with a wide margin (full:
// kFullCadenceTolerance, confirm_full.hpp). Power mode: the cycle's mean dissipated power within
// 1e-8 of P, in at most 30 load searches (the secant converges in 3–6).
constexpr double kReducedCadenceTolerance = 1e-6;
constexpr double kPowerTolerance = 1e-8;
// Drive and dissipated power on the reduced cycle may differ by this (bicycle 1 Hz, 125 W: 1.2e-6).
constexpr double kEnergyBalanceTolerance = 1e-3;
constexpr int kMaxPowerPasses = 30;

// A calibration must meet its own target (issue #9): a cadence off by more than `tolerance`
// (relative) is a numerical failure, naming what was measured (`what`) at which load value.
void check_cadence(const char* what, double measured_hz, double target_hz, double tolerance, const Selection& sel,
                   double value) {
  const double miss = std::abs(measured_hz - target_hz) / target_hz;
  if (!(miss <= tolerance))
    throw models::NumericalError(fmt::format("{} is {:.6g} Hz at {} = {:.6g} {}, target {:g} Hz (off by {:.3g} %, "
                                             "allowed {:g} %)",
                                             what, measured_hz, sel.name, value, sel.unit, target_hz, 100 * miss,
                                             100 * tolerance));
}

struct Cycle {
  bool ok = false;
  double speed = 0.0, period = 0.0;  // q̇ at the section q = q_s on the steady cycle; [s]
  reduced::SteadyCycle detail;   // extremes, work, counts (when ok)
  std::string why;               // the search's message (when not ok)
};

// Steady cycle of the reduced model at section q_s (reduced/steady_cycle.hpp): by the first
// integral of Eksergian's equation, by time stepping (Poincaré map) where q̇ does not keep its
// sign. Not ok when neither finds one (a stall). `extremes`: also sample the cycle for the
// speed fluctuation and the peak constraint forces.
Cycle steady_cycle(const reduced::ReducedModel& m, double q_s, double v_guess, double tol, int& evals,
                   bool extremes = false) {
  reduced::SteadyCycleOptions o;
  o.q_section = q_s;
  o.qdot_guess = v_guess;
  o.tolerance = tol;
  o.extremes = extremes;
  try {
    const auto c = reduced::find_steady_cycle(m, o);
    evals += c.passes;
    return {true, c.qdot_section, c.period_s, c, {}};
  } catch (const models::NumericalError& e) {
    return {false, 0.0, 0.0, {}, e.what()};  // (the failed search's passes are not counted)
  }
}

struct RootContext {
  reduced::ReducedModel* m;
  const Selection* sel;
  double q_s, v_guess, target_hz, tol;
  int* evals;
};

double cadence_error(double T, void* p) {
  auto* c = static_cast<RootContext*>(p);
  set_load(*c->m, *c->sel, T);
  const Cycle cy = steady_cycle(*c->m, c->q_s, c->v_guess, c->tol, *c->evals);
  return (cy.ok ? 1.0 / cy.period : 0.0) - c->target_hz;
}

struct FullCheck {
  SteadyConfirmation c;
  int revolutions = 0;  // m of the measure
};

// The full model at the calibrated values, started from the reduced steady cycle's point: its
// one initial state is q and q̇ of that cycle at the same phase (the scene's own initial speed,
// whether it gave qdot or cadence_Hz, and its q are replaced, never combined), run until steady.
FullCheck confirm_on_full(const models::Scene& scene, const CalibrationOptions& opt, const CalibrationResult& r) {
  const models::Scene sf = scene_at_operating_point(scene, opt, r);
  SteadyConfirmOptions fc;
  fc.cadence_hz = r.mean_cadence_hz_reduced;
  fc.max_duration_s = opt.full_max_s;
  // ≥ 360 rows a turn: at 100 Hz 2 ms rows were 72° apart (force peak 26075 N for 40176 N).
  fc.output_interval_s = std::min(fc.output_interval_s, 1.0 / (360.0 * r.mean_cadence_hz_reduced));
  return {confirm_full_steady(sf, fc), fc.revolutions};
}

// A confirmation that did not settle within the cap, or settled away from F, is exit 1; the
// message gives the reduced operating point and what the full model reached.
void check_full(const FullCheck& full, const CalibrationOptions& opt, const Selection& sel,
                const CalibrationResult& r) {
  const auto& mz = full.c.measures;
  const double miss = std::abs(mz.cadence_hz - opt.cadence_hz) / opt.cadence_hz;
  if (full.c.steady && miss <= kFullCadenceTolerance) return;
  const std::string reduced_point = fmt::format(
      "the reduced operating point: {} = {:.6g} {}{}, steady cycle through q = {:.6g}° at q̇ = {:.6g} rad/s, "
      "mean cadence {:.6g} Hz",
      sel.name, r.load_value, sel.unit,
      std::isfinite(r.resistance_coefficient) ? fmt::format(", resistance coefficient {:.6g}", r.resistance_coefficient)
                                              : std::string(),
      r.steady_q * 180 / M_PI, r.steady_qdot, r.mean_cadence_hz_reduced);
  const int m = full.revolutions;
  std::string reached = fmt::format("{} whole revolutions in {:g} s of simulated time", mz.revolutions,
                                    full.c.duration_s);
  if (!std::isfinite(mz.cadence_hz))
    reached += fmt::format(", fewer than the {} the steady test compares", 2 * m);
  else if (!std::isfinite(mz.previous_cadence_hz))
    reached += fmt::format("; mean cadence {:.6g} Hz over the last {} (fewer than the {} the steady test compares)",
                           mz.cadence_hz, m, 2 * m);
  else
    reached += fmt::format("; mean cadence {:.6g} Hz over the last {} and {:.6g} Hz over the {} before",
                           mz.cadence_hz, m, mz.previous_cadence_hz, m);
  if (!full.c.steady)
    throw models::NumericalError(fmt::format(
        "calibration not confirmed: the full model is not steady within {:g} s of simulated time (steady: the mean "
        "cadence of the last {} whole revolutions within {:g} % of the {} before); it reached {}; {}",
        opt.full_max_s, full.revolutions, 100 * SteadyConfirmOptions{}.steady_tolerance, full.revolutions, reached,
        reduced_point));
  throw models::NumericalError(fmt::format(
      "calibration not confirmed: the full model's steady mean cadence over whole revolutions is {:.6g} Hz, target "
      "{:g} Hz (off by {:.3g} %, allowed {:g} %); it reached {}; {}",
      mz.cadence_hz, opt.cadence_hz, 100 * miss, 100 * kFullCadenceTolerance, reached, reduced_point));
}

}  // namespace

CalibrationOptions calibration_options_of(const models::Scene& scene, double cadence_hz, double power_w,
                                          const std::string& load) {
  CalibrationOptions o;
  const auto& v = scene.validation;
  o.cadence_hz = cadence_hz > 0 ? cadence_hz : v.calibrate_cadence_Hz;
  o.power_w = power_w > 0 ? power_w : v.calibrate_power_W;
  o.load = !load.empty() ? load : v.calibrate_load;
  o.load_field = !load.empty() ? "--load" : "validation.calibrate.load";
  o.grid_deg = v.calibrate_grid_deg;
  o.grid_given = v.calibrate_grid_given;
  return o;
}

std::string load_value_column(const models::Scene& scene, const CalibrationOptions& opt) {
  const Selection sel = select_load(scene, opt);
  const bool joint = sel.kind.rfind("joint", 0) == 0;
  if (sel.unit == "N·m") return joint ? "drive_torque_Nm" : sel.kind + "_Nm";
  if (sel.unit == "N") return sel.kind == "joint_torques" && !sel.together ? "drive_force_N" : sel.kind + "_N";
  return "drive_load";
}

namespace {

// check_calibratable without the full model: options, the load, the resistance, a revolute
// without a range.
void check_calibration_input(const models::Scene& scene, const CalibrationOptions& opt) {
  auto fail = [&](const std::string& field, const std::string& msg) {
    throw models::SceneError(scene.source_file, scene.line_of(field), scene.field_of(field), msg);
  };
  if (!(opt.cadence_hz > 0)) fail("--cadence-hz", "must be positive");
  if (!(opt.power_w >= 0)) fail("--power-w", "must be positive");
  select_load(scene, opt);
  if (opt.power_w > 0) {
    if (scene.resistances.size() != 1)
      fail("loads", fmt::format("a power to dissipate needs exactly one resistance (the scene has {}); without "
                                "--power-w the resistances stay as given and only the load changes",
                                scene.resistances.size()));
    const auto& res = scene.resistances[0];
    if (!models::fixed_speed_ratio(scene, res.body))
      fail("loads." + res.name, "the resistance's body must turn at a fixed ratio to the independent coordinate");
  }
  // The mean speed is set by losses that grow with speed (viscous, quadratic resistances) or a
  // drive that falls with it (a motor). Resistances of constant magnitude take the same energy
  // per revolution at every speed, and torques and forces depend on position only: then every
  // speed is a steady cycle at the one load value that balances a revolution, and none is
  // singled out (the calibrated "cadence" would be an accident of interpolation errors).
  bool speed_sets_losses = !scene.motors.empty();
  for (const auto& res : scene.resistances) speed_sets_losses |= res.law != models::ResistanceLaw::Constant;
  if (!speed_sets_losses && !scene.resistances.empty())
    throw models::SceneError(
        scene.source_file, scene.line_of("loads." + scene.resistances[0].name), "loads." + scene.resistances[0].name,
         fmt::format("every resistance has a constant magnitude (law: constant), which takes the same energy per "
                     "revolution at any speed, and no motor drives: every speed is then a steady cycle at one load "
                     "value, so no load value holds {:g} Hz rather than another; give a resistance a viscous or "
                     "quadratic law, or drive with a motor",
                     opt.cadence_hz));
  // A mean rate in rev/s needs a coordinate that turns fully: a rocker or a stroke moves within
  // a range (docs/theory.md §6c) and has no steady revolution to hold.
  const auto* indep = scene.find_joint(scene.independent);
  if (indep->type != models::JointType::Revolute || scene.independent_range)
    fail("independent", fmt::format("calibration holds a mean rate in rev/s, so '{}' must be a revolute that turns "
                                    "fully; it moves within a range",
                                    scene.independent));
}

void fail_dead_points(const models::Scene& scene) {
  throw models::SceneError(scene.source_file, scene.line_of("independent"), scene.field_of("independent"),
                           fmt::format("calibration holds a mean rate in rev/s, so '{}' must turn fully; it cannot "
                                       "(it meets dead points: see rdyn inspect)",
                                       scene.independent));
}

// check_calibratable's full-model part on a built system.
void check_full_turn(const models::Scene& scene, const engine::FullModel& model) {
  const engine::FullWorkspace assembled(model);  // throws EngineError naming a loop that cannot close
  // The walk alone: a turn is full or not whatever singular points it holds (the scan for them
  // was 90 % of a sweep case over the rider's height).
  if (!engine::calc_independent_domain_edges(model).periodic) fail_dead_points(scene);
}

CalibrationTable table_of(Extraction e, const CalibrationOptions& opt, bool walked, double grid_deg,
                          const std::optional<std::vector<std::string>>& columns) {
  CalibrationTable t;
  t.grid_deg = grid_deg;
  t.samples = columns ? reduced::select_columns(e.samples, *columns) : std::move(e.samples);
  t.table = reduced::build_table(t.samples, reduced::parse_interpolation(opt.interpolation));
  t.walked = walked;
  return t;
}

}  // namespace

void check_calibratable(const models::Scene& scene, const CalibrationOptions& opt) {
  check_calibration_input(scene, opt);
  check_full_turn(scene, engine::FullModel(scene));
}

double calc_resistance_coefficient(const models::Scene& scene, const CalibrationOptions& opt) {
  if (!(opt.power_w > 0)) return NAN;  // mean-speed mode: the resistances stay as given
  const auto& res = scene.resistances[0];
  const double omega_b = std::abs(*models::fixed_speed_ratio(scene, res.body)) * 2 * M_PI * opt.cadence_hz;
  return opt.power_w / std::pow(omega_b, models::dissipation_exponent(res.law));  // P = c·ω^n
}

models::Scene with_unit_load(const models::Scene& scene, const CalibrationOptions& opt) {
  return with_load(scene, select_load(scene, opt), 1.0, calc_resistance_coefficient(scene, opt));
}

namespace {

[[noreturn]] void fail_field(const models::Scene& scene, const std::string& field, const std::string& msg) {
  throw models::SceneError(scene.source_file, scene.line_of(field), scene.field_of(field), msg);
}

// The energy balance's first guess T0 = −W_other/W_unit, after refusing (exit 2, naming the load
// field) a load that cannot set the mean speed: no net work per revolution, work of the wrong
// sign (a motor past its no-load speed), other drive loads that already supply what the
// resistances dissipate, or nothing that dissipates.
double calc_energy_balance_guess(const RevolutionWork& w, const models::Scene& scene, const Selection& sel,
                                 const CalibrationOptions& opt, const std::string& load_field) {
  const bool motor = sel.kind.rfind("motor", 0) == 0;
  if (!(std::abs(w.unit) > 1e-9 * w.scale) && !motor)
    fail_field(scene, load_field,
               fmt::format("'{}' does no net work per revolution ({:.3g} J per {}), so it cannot change the "
                           "mean speed: calibrate a load that drives the mechanism",
                           sel.name, w.unit, sel.unit));
  if (!(w.unit > 0)) {
    if (motor)
      fail_field(scene, load_field,
                 fmt::format("motor '{}' cannot hold {:g} Hz: there its joint turns at up to {:.4g} times its no-load "
                             "speed {:g}, so the motor does {:.3g} J per revolution per {} of stall torque; no stall "
                             "torque of the no-load speed's sign holds the target (lower the target or raise the "
                             "no-load speed)",
                             sel.name, opt.cadence_hz, w.max_motor_rate,
                             scene.motors[sel.entries[0].index].no_load_speed, w.unit, sel.unit));
    fail_field(scene, load_field,
               fmt::format("'{}' does negative work per revolution with the sign it has in the scene ({:.3g} J "
                           "per {}): give it the opposite sign",
                           sel.name, w.unit, sel.unit));
  }
  // The resistances dissipate but other drive loads already supply it (e.g. a scene's muscles
  // calibrated for this operating point, and a torque added beside them): the selected load
  // has no work left to do. Name those loads: "nothing dissipates" would be untrue.
  std::string drivers;
  auto add_driver = [&](const std::string& name, double W) {
    if (W > 1e-9 * w.other_scale) drivers += fmt::format("{}'{}' {:+.4g} J", drivers.empty() ? "" : ", ", name, W);
  };
  for (size_t k = 0; k < w.torque.size(); ++k) add_driver(scene.joint_torques[k].name, w.torque[k]);
  for (size_t k = 0; k < w.force.size(); ++k) add_driver(scene.point_forces[k].name, w.force[k]);
  for (size_t k = 0; k < w.motor.size(); ++k) add_driver(scene.motors[k].name, w.motor[k]);
  if (!(w.other < -1e-9 * w.other_scale) && w.brakes < -1e-9 * w.other_scale && !drivers.empty())
    fail_field(scene, load_field,
               fmt::format("at {:g} Hz the other drive loads already supply what the resistances dissipate "
                           "({:.4g} J per revolution): {} ({:+.3g} J net), so '{}' has no work left to do "
                           "and cannot set the mean speed; calibrate those loads instead, or remove them",
                           opt.cadence_hz, w.brakes, drivers, w.other, sel.name));
  // Below round-off of the other loads' work: nothing dissipates (a constant force on a slider
  // returns its work over a revolution).
  if (!(w.other < -1e-9 * w.other_scale) || w.other == 0.0)
    fail_field(scene, load_field,
               fmt::format("nothing dissipates energy at {:g} Hz (the other loads do {:.3g} J per revolution): "
                           "'{}' cannot hold a mean speed; give a power to dissipate (--power-w, "
                           "validation.calibrate.power_W) or a resistance",
                           opt.cadence_hz, w.other, sel.name));
  return -w.other / w.unit;
}

// One Newton iteration for the cycle, the load and (power mode) the coefficient together, from
// the energy balance's guess (validate/analysis/operating_point.hpp); empty where there is no
// first integral (a table that is not periodic): the nested searches then.
std::optional<OperatingPoint> solve_direct(reduced::ReducedModel& m, const Selection& sel, const models::Scene& scene,
                                           const CalibrationOptions& opt, const CalibrationResult& r, bool power_mode,
                                           int& evals, Progress& progress) {
  OperatingPointTargets tg;
  tg.q_section = scene.initial.q;
  tg.qdot_guess = 2 * M_PI * opt.cadence_hz;
  tg.cadence_hz = opt.cadence_hz;
  tg.power_w = power_mode ? opt.power_w : NAN;
  tg.tolerance = opt.tolerance;
  progress.note("calibrate: operating point (Newton on the first integral)");
  try {
    return solve_operating_point(
        m, tg, r.initial_guess, r.resistance_coefficient,
        [&](double load, double c) {
          set_load(m, sel, load);
          if (power_mode) m.brakes[0].coefficient = c;
        },
        evals);
  } catch (const models::NumericalError&) {
    return std::nullopt;
  }
}

// Brent (GSL) on the load's magnitude until the mean steady cadence is F, from a bracket around
// the energy balance's guess widened (at most 20 times each way) until it holds the root.
double search_load(reduced::ReducedModel& m, const Selection& sel, const models::Scene& scene,
                   const CalibrationOptions& opt, double guess, int& evals, Progress& progress) {
  RootContext ctx{&m, &sel, scene.initial.q, 2 * M_PI * opt.cadence_hz, opt.cadence_hz, opt.tolerance, &evals};
  gsl_function fn{cadence_error, &ctx};
  double lo = 0.8 * guess, hi = 1.25 * guess;
  double flo = cadence_error(lo, &ctx), fhi = cadence_error(hi, &ctx);
  for (int i = 0; i < 20 && flo > 0; ++i) lo *= 0.7, flo = cadence_error(lo, &ctx);
  for (int i = 0; i < 20 && fhi < 0 && hi < models::limits::kMaxForce; ++i)
    hi = std::min(hi * 1.4, models::limits::kMaxForce), fhi = cadence_error(hi, &ctx);
  if (!(flo <= 0 && fhi >= 0))
    throw models::NumericalError(fmt::format("calibration: no value of '{}' between {:.4g} and {:.4g} {} holds {} Hz",
                                             sel.name, lo, hi, sel.unit, opt.cadence_hz));
  gsl_set_error_handler_off();
  std::unique_ptr<gsl_root_fsolver, decltype(&gsl_root_fsolver_free)> solver(
      gsl_root_fsolver_alloc(gsl_root_fsolver_brent), gsl_root_fsolver_free);
  gsl_root_fsolver_set(solver.get(), &fn, lo, hi);
  double T = guess;
  for (int it = 0; it < 100; ++it) {
    gsl_root_fsolver_iterate(solver.get());
    T = gsl_root_fsolver_root(solver.get());
    progress.count("calibrate: load search", it + 1, it + 1);
    if (gsl_root_test_interval(gsl_root_fsolver_x_lower(solver.get()), gsl_root_fsolver_x_upper(solver.get()), 0,
                               1e-10 * std::max(1.0, std::abs(T))) == GSL_SUCCESS)
      break;
  }
  return T;
}

// A value the scene format refuses (|load| or |amplitude|·max|τ| above limits::kMaxForce, a
// resistance coefficient beyond its body's bound) is no result: a written scene would not load.
void check_scene_allows(const models::Scene& scene, const Selection& sel, double T, double coefficient,
                        const CalibrationOptions& opt) {
  try {
    models::check_scene(with_load(scene, sel, T, coefficient));
  } catch (const models::SceneError& e) {
    throw models::NumericalError(fmt::format(
        "calibration: holding {:g} Hz needs {} = {:.6g} {}, beyond what a scene allows (the limit is {:g} {} per "
        "load): {}: {}; choose a lower power or another operating point",
        opt.cadence_hz, sel.name, T, sel.unit, models::limits::kMaxForce, sel.unit, e.field(), e.message()));
  }
}

// The reduced model's steady cycle at load magnitude T, sampled for its extremes, into r (load
// value with its sign, operating point, mean cadence); it must meet its own target (issue #9):
// the root finders converge to 1e-10 relative, so the cadence is off by far less than
// kReducedCadenceTolerance unless the bracket held a discontinuity (a stall) instead of a root.
Cycle settle_at_load(reduced::ReducedModel& m, const Selection& sel, const models::Scene& scene,
                     const CalibrationOptions& opt, double T, double qdot_guess, int& evals, CalibrationResult& r) {
  const double sign = sel.entries[0].sign;
  r.load_value = sel.kind == "joint_torques" || sel.together ? T : sign * T;
  r.torque_Nm = sel.unit == "N·m" && sel.kind.rfind("joint", 0) == 0 ? T : NAN;  // NaN for point forces
  set_load(m, sel, T);
  Cycle cy = steady_cycle(m, scene.initial.q, qdot_guess, opt.tolerance, evals, true);
  if (!cy.ok)
    throw models::NumericalError(fmt::format("calibration: the reduced model has no steady cycle at the value found "
                                             "({:.6g} {}): {}", r.load_value, sel.unit, cy.why));
  r.steady_q = scene.initial.q;
  r.steady_qdot = cy.speed;
  r.mean_cadence_hz_reduced = 1.0 / cy.period;
  check_cadence("calibration missed its target: the reduced model's steady cadence", r.mean_cadence_hz_reduced,
                opt.cadence_hz, kReducedCadenceTolerance, sel, r.load_value);
  return cy;
}

// Power mode: c = P/ω_Fⁿ dissipates P only at constant speed; on a fluctuating steady cycle the
// resistance dissipates c·⟨ωⁿ⟩ ≠ P (a motor-driven crank at 2.3× fluctuation: 25 W for 20 W).
// So the coefficient is adjusted too, around the load search, until the steady cycle both holds
// F (the load) and dissipates P (the coefficient): a secant on ln c ↦ ln(P_diss/P), whose slope
// is near 1 (P_diss = c·⟨ωⁿ⟩, ⟨ωⁿ⟩ nearly independent of c), at most kMaxPowerPasses load
// searches. True when the cycle dissipates P; otherwise the next coefficient into r.
struct PowerSecant {
  double ln_c_prev = NAN, f_prev = NAN;
};
bool power_met(const Cycle& cy, const CalibrationOptions& opt, int pass, PowerSecant& s, CalibrationResult& r) {
  const double P_diss = cy.detail.dissipated_power_W;
  const double f = std::log(P_diss / opt.power_w);  // 0 at the target
  if (!std::isfinite(f))
    throw models::NumericalError(fmt::format("calibration: the resistance dissipates {:.6g} W on the steady cycle "
                                             "at {:g} Hz; no coefficient reaches {:g} W",
                                             P_diss, opt.cadence_hz, opt.power_w));
  if (std::abs(f) <= kPowerTolerance) return true;
  if (pass + 1 >= kMaxPowerPasses)
    throw models::NumericalError(fmt::format(
        "calibration did not converge: after {} load searches the steady cycle at {:g} Hz dissipates {:.8g} W "
        "(resistance coefficient {:.6g}), target {:g} W (allowed {:g} %)",
        pass + 1, opt.cadence_hz, P_diss, r.resistance_coefficient, opt.power_w, 100 * kPowerTolerance));
  const double ln_c = std::log(r.resistance_coefficient);
  double slope = std::isfinite(s.ln_c_prev) && ln_c != s.ln_c_prev ? (f - s.f_prev) / (ln_c - s.ln_c_prev) : 1.0;
  if (!(slope > 0.1 && slope < 10)) slope = 1.0;  // a wild secant: the fixed-point step
  s.ln_c_prev = ln_c, s.f_prev = f;
  r.resistance_coefficient = std::exp(ln_c - f / slope);
  return false;
}

// On a steady cycle the drive supplies what the resistances dissipate. The reduced model's own
// residual — an interpolated m2 that is not exactly ½ dm1/dq acts as a power ∝ q̇³ (docs/theory.md
// §5; ~1.5e-4 W on the bicycle's 10° table at 1 Hz, 1e-6 of 125 W) — is small unless the
// operating point's energy flow is small against it (a very low power, a very high cadence):
// then the calibrated value is the interpolation error's, not the mechanism's, and that is no
// result.
void check_cycle_energy_balance(const Cycle& cy, const CalibrationOptions& opt) {
  const double drive = cy.detail.drive_power_W, diss = cy.detail.dissipated_power_W;
  if (!(std::abs(drive - diss) <= kEnergyBalanceTolerance * std::max(std::abs(drive), std::abs(diss))))
    throw models::NumericalError(fmt::format(
        "calibration: on the reduced model's steady cycle at {:g} Hz the drive supplies {:.6g} W but the resistances "
        "dissipate {:.6g} W ({:.2g} % apart, allowed {:g} %): the table's interpolation error is not small against "
        "this operating point's energy flow; extract on a finer grid (--grid-deg)",
        opt.cadence_hz, drive, diss, 100 * std::abs(drive - diss) / std::max(std::abs(drive), std::abs(diss)),
        100 * kEnergyBalanceTolerance));
}

// A motor's mean power depends on the speed: the trapezoid rule over the periodic cycle's
// samples (spectrally accurate for a smooth periodic integrand).
double calc_motor_mean_power(const reduced::ReducedModel& m, const reduced::ReducedModel::Motor& mo,
                             const CalibrationResult& r, const Cycle& cy, double tolerance) {
  reduced::ReducedOptions ro;
  ro.duration_s = cy.period;
  ro.output_interval_s = cy.period / 1440;
  ro.tolerance = tolerance;
  const auto cyc = reduced::simulate_reduced(m, r.steady_q, r.steady_qdot, ro);
  double E = 0.0;
  for (size_t i = 0; i + 1 < cyc.t.size(); ++i) {
    auto p = [&](size_t k) {
      const double u = m.table.eval(mo.c_r, cyc.q[k]) * cyc.qdot[k];
      return models::motor_torque(mo.stall, mo.no_load_speed, u) * u;
    };
    E += 0.5 * (p(i) + p(i + 1)) * (cyc.t[i + 1] - cyc.t[i]);
  }
  return E / cy.period;
}

}  // namespace

// Stages: the work per revolution at the target rate gives the first guess; Newton on the
// operating point (or Brent on the load) holds the cadence; the steady cycle at that load is
// checked against its target; in power mode the resistance coefficient is corrected and the load
// searched again until the cycle dissipates P; then the cycle's energy balance, extremes and
// mean power.
CalibrationResult calibrate_reduced(const reduced::ReducedModel& model, const models::Scene& scene,
                                    const CalibrationOptions& opt, Progress& progress) {
  return calibrate_reduced(reduced::ReducedModel(model), scene, opt, progress);  // a copy (issue #23)
}

CalibrationResult calibrate_reduced(reduced::ReducedModel&& m, const models::Scene& scene,
                                    const CalibrationOptions& opt, Progress& progress) {
  const Selection sel = select_load(scene, opt);
  const std::string load_field = opt.load.empty() ? "loads" : opt.load_field;
  CalibrationResult r;
  r.load = sel.name;
  r.load_kind = sel.kind;
  r.load_unit = sel.unit;
  r.resistance_coefficient = calc_resistance_coefficient(scene, opt);
  const bool power_mode = std::isfinite(r.resistance_coefficient);
  if (power_mode && m.brakes.size() != 1)
    throw models::NumericalError(fmt::format("calibration: the reduced model has {} resistances, the power mode one",
                                             m.brakes.size()));
  double T = 0.0;
  RevolutionWork work;
  PowerSecant secant;
  int evals = 0;
  Cycle cy;
  for (int pass = 0;; ++pass) {
    if (power_mode) m.brakes[0].coefficient = r.resistance_coefficient;
    set_load(m, sel, 1.0);  // the energy balance reads the selected loads at unit value
    work = calc_revolution_work(m, sel, scene.initial.q, opt.cadence_hz);
    r.work_per_rev_per_unit = work.unit;
    r.initial_guess = calc_energy_balance_guess(work, scene, sel, opt, load_field);
    std::optional<OperatingPoint> direct;
    if (opt.direct && pass == 0) direct = solve_direct(m, sel, scene, opt, r, power_mode, evals, progress);
    if (direct) {
      T = direct->load;
      if (power_mode) r.resistance_coefficient = direct->coefficient;
    } else {
      if (power_mode) m.brakes[0].coefficient = r.resistance_coefficient;
      T = search_load(m, sel, scene, opt, r.initial_guess, evals, progress);
    }
    progress.note("");
    check_scene_allows(scene, sel, T, r.resistance_coefficient, opt);
    cy = settle_at_load(m, sel, scene, opt, T, direct ? direct->qdot_section : 2 * M_PI * opt.cadence_hz, evals, r);
    r.load_searches = pass + 1;
    if (!power_mode || power_met(cy, opt, pass, secant, r)) break;
  }
  r.mean_dissipated_power_w = cy.detail.dissipated_power_W;
  check_cycle_energy_balance(cy, opt);
  r.evaluations = evals;

  // Fluctuation and peak force over the steady cycle (sampled and refined by steady_cycle).
  r.speed_fluctuation = cy.detail.speed_fluctuation;
  if (!scene.outputs.constraint_forces.empty()) {
    r.force_name = scene.outputs.constraint_forces[0].name;
    r.peak_force_N = cy.detail.peak_force_N[0];
  }
  r.peak_forces_N = cy.detail.peak_force_N;
  r.mean_power_w = sel.entries[0].motor
                       ? calc_motor_mean_power(m, m.motors[sel.entries[0].index], r, cy, opt.tolerance)
                       : T * work.unit / cy.period;  // a position-dependent load: its work per revolution is exact
  r.mean_cadence_hz_full = r.speed_fluctuation_full = r.peak_force_full_N = NAN;
  return r;
}

CalibrationTable extract_calibration_table(const models::Scene& scene, const CalibrationOptions& opt) {
  CalibrationTable t = extract_calibration_table(scene, opt, std::nullopt);
  if (t.grid_deg != opt.grid_deg)
    std::fprintf(stderr, "rdyn: the %g° table does not resolve this mechanism (m1's or Q_cons's half-grid miss above %g): "
                 "calibrating on a %g° table\n", opt.grid_deg, kAutoRefineMiss, t.grid_deg);
  return t;
}

CalibrationTable extract_calibration_table(const models::Scene& scene, const CalibrationOptions& opt,
                                           const std::optional<TableNeighbour>& neighbour,
                                           const std::optional<std::vector<std::string>>& columns) {
  // Dead points are looked for twice, because each route alone misses some: the domain walk
  // (check_calibratable; its plain 10° moves miss a blocked range of 2–3° from some starts) and
  // the extraction's closed turn (reduced::SweepNotClosed; a coarse sweep that steps over the
  // blocked range twice comes back on its branch and closes). One system serves both.
  check_calibration_input(scene, opt);
  const engine::FullModel model(scene);
  const bool continued = neighbour && neighbour->min_conditioning >= kWalkSkipConditioning &&
                         neighbour->topology == topology_key(scene);
  double grid = opt.grid_deg;  // refined quietly: a sweep's cases
  if (!continued) {
    check_full_turn(scene, model);
    auto e = extract_resolving(model, opt.grid_deg, opt.grid_given, reduced::Method::Kinetostatic, false, grid);
    if (e.range || !e.samples.periodic) fail_dead_points(scene);
    return table_of(std::move(e), opt, true, grid, columns);
  }
  // Continuation from a neighbour far from dead points: the extraction first, the walk only where
  // this case's own sweep gives a reason (a failure, a dead point, a grid sample nearer rank loss
  // than kWalkSkipConditioning or kWalkSkipDrop of the neighbour's); its errors after the walk's.
  Extraction e;
  try {
    e = extract_resolving(model, opt.grid_deg, opt.grid_given, reduced::Method::Kinetostatic, false, grid);
  } catch (...) {
    check_full_turn(scene, model);
    throw;
  }
  const double c = e.samples.min_conditioning;
  const bool walk = e.range || !e.samples.periodic || !(c >= kWalkSkipConditioning) ||
                    !(c >= kWalkSkipDrop * neighbour->min_conditioning);
  if (walk) check_full_turn(scene, model);
  if (e.range || !e.samples.periodic) fail_dead_points(scene);
  return table_of(std::move(e), opt, walk, grid, columns);
}

CalibrationResult calibrate(const models::Scene& scene, const CalibrationOptions& opt, Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  // The table does not depend on load values: extract once.
  progress.note("calibrate: extracting the reduced table");
  auto r = calibrate(scene, extract_calibration_table(scene, opt), opt, progress);
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

CalibrationResult calibrate(const models::Scene& scene, const CalibrationTable& table, const CalibrationOptions& opt,
                            Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  check_calibration_input(scene, opt);
  const Selection sel = select_load(scene, opt);
  CalibrationResult r = calibrate_reduced(
      reduced::make_reduced_model(table.samples, with_unit_load(scene, opt), table.table), scene, opt, progress);
  r.grid_deg = table.grid_deg > 0 ? table.grid_deg : opt.grid_deg;

  // Confirmation with the full model from the same point of the steady cycle.
  r.mean_cadence_hz_full = r.speed_fluctuation_full = r.peak_force_full_N = NAN;
  if (!(opt.full_max_s > 0)) {
    r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  }
  progress.note("calibrate: confirming with the full model");
  const FullCheck full = confirm_on_full(scene, opt, r);
  r.mean_cadence_hz_full = full.c.measures.cadence_hz;
  r.speed_fluctuation_full = full.c.measures.speed_fluctuation;
  r.peak_force_full_N = full.c.measures.peak_force_N;
  r.full_revolutions = full.c.measures.revolutions;
  r.full_duration_s = full.c.duration_s;
  try {
    check_full(full, opt, sel, r);
  } catch (const models::NumericalError& e) {
    if (!opt.keep_unconfirmed) throw;
    r.unconfirmed = e.what();
  }
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace rdyn::validate
