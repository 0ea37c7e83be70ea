#include "validate/calibrate.hpp"

#include <chrono>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "reduced/steady_cycle.hpp"
#include "validate/build_reduced.hpp"

namespace rdyn::validate {

namespace {

// Acceptance of a calibration (relative cadence error). Reduced: the steady cycle is solved
// to 1e-12 and the torque to 1e-10 N·m, so 1e-6 is met with a wide margin by any genuine
// root. Full: the reduced table's own error (≈ 1e-5 of the speed at 10°, docs/theory.md) and
// the 5 s window's quasi-steady drift keep the full model within 1e-4; 1 % is the user-level
// target (issue #13: "holds 1 Hz within 1 %").
constexpr double kReducedCadenceTolerance = 1e-6;
constexpr double kFullCadenceTolerance = 1e-2;

// The scene with its one resistance dissipating P at cadence F and every drive torque set
// to ±T (signs kept).
models::Scene with_loads(models::Scene s, double T, double coefficient) {
  for (auto& t : s.joint_torques) t.value = (t.value < 0 ? -1.0 : 1.0) * T;
  s.resistances[0].coefficient = coefficient;
  return s;
}

struct Cycle {
  bool ok = false;
  double speed = 0.0;            // q̇ at the section q = q_s on the steady cycle
  double period = 0.0;           // [s]
  reduced::SteadyCycle detail;   // extremes, work, counts (when ok)
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
    return {true, c.qdot_section, c.period_s, c};
  } catch (const models::NumericalError&) {
    return {};  // (the failed search's passes are not counted)
  }
}

struct RootContext {
  reduced::ReducedModel* m;
  double q_s, v_guess, target_hz, tol;
  int* evals;
};

double cadence_error(double T, void* p) {
  auto* c = static_cast<RootContext*>(p);
  for (auto& t : c->m->torques) t.value = (t.value < 0 ? -1.0 : 1.0) * T;
  const Cycle cy = steady_cycle(*c->m, c->q_s, c->v_guess, c->tol, *c->evals);
  return (cy.ok ? 1.0 / cy.period : 0.0) - c->target_hz;
}

}  // namespace

void check_calibratable(const models::Scene& scene, const CalibrationOptions& opt) {
  auto fail = [&](const std::string& field, const std::string& msg) {
    throw models::SceneError(scene.source_file, 0, field, msg);
  };
  if (scene.joint_torques.empty()) fail("loads", "calibration needs at least one joint torque to scale");
  if (scene.resistances.size() != 1) fail("loads", "calibration needs exactly one resistance");
  if (!(opt.cadence_hz > 0) || !(opt.power_w > 0)) fail("--cadence-hz/--power-w", "must be positive");
  const auto& res = scene.resistances[0];
  if (!models::fixed_speed_ratio(scene, res.body))
    fail("loads." + res.name, "the resistance's body must turn at a fixed ratio to the independent coordinate");
  const engine::FullModel model(scene);
  const engine::FullWorkspace assembled(model);  // throws EngineError naming a loop that cannot close
}

CalibrationResult calibrate(const models::Scene& scene, const CalibrationOptions& opt, Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  auto fail = [&](const std::string& field, const std::string& msg) {
    throw models::SceneError(scene.source_file, 0, field, msg);
  };
  check_calibratable(scene, opt);
  const auto& res = scene.resistances[0];
  const auto ratio = models::fixed_speed_ratio(scene, res.body);
  CalibrationResult r;
  const double omega_b = std::abs(*ratio) * 2 * M_PI * opt.cadence_hz;
  r.resistance_coefficient = opt.power_w / std::pow(omega_b, models::dissipation_exponent(res.law));  // P = c·ω^n

  // The table does not depend on load values: extract once.
  progress.note("calibrate: extracting the reduced table");
  const auto e = extract_from_full(scene, opt.grid_deg, reduced::Method::Kinetostatic);
  models::Scene s1 = with_loads(scene, 1.0, r.resistance_coefficient);
  auto m = reduced::make_reduced_model(e.samples, s1, reduced::parse_interpolation(opt.interpolation));

  // First guess from the energy balance per revolution at constant cadence: drive work
  // T·Σ∫ r_j [gate] dq equals the dissipation ∫ −T_b(w q̇) w dq.
  const int n = 3600;
  const double qd = 2 * M_PI * opt.cadence_hz, dq = 2 * M_PI / n;
  double W_unit = 0.0, E_diss = 0.0;
  for (int i = 0; i < n; ++i) {
    const double q = scene.initial.q + (i + 0.5) * dq;
    for (const auto& t : m.torques) {
      const bool on = t.gate < 0 || m.gates[t.gate].sign * m.table.eval(m.gates[t.gate].c_r, q) * qd > 0;
      const double tau = t.c_tau >= 0 ? m.table.eval(t.c_tau, q) : 1.0;  // profiled: τ(θ(q)) per unit value
      if (on) W_unit += (t.value < 0 ? -1.0 : 1.0) * tau * m.table.eval(t.c_r, q) * dq;
    }
    const auto& b = m.brakes[0];
    const double w = m.table.eval(b.c_w, q);
    E_diss += -models::resistance_torque(b.law, b.coefficient, w * qd) * w * dq;
  }
  if (!(W_unit > 0)) fail("loads", "the drive torques do no net work per revolution at this cadence");
  r.drive_work_per_rev_per_Nm = W_unit;
  r.initial_guess_Nm = E_diss / W_unit;

  // Brent (GSL) on the torque: mean steady cadence = F.
  int evals = 0;
  RootContext ctx{&m, scene.initial.q, qd, opt.cadence_hz, opt.tolerance, &evals};
  gsl_function fn{cadence_error, &ctx};
  double lo = 0.8 * r.initial_guess_Nm, hi = 1.25 * r.initial_guess_Nm;
  double flo = cadence_error(lo, &ctx), fhi = cadence_error(hi, &ctx);
  for (int i = 0; i < 20 && flo > 0; ++i) lo *= 0.7, flo = cadence_error(lo, &ctx);
  for (int i = 0; i < 20 && fhi < 0; ++i) hi *= 1.4, fhi = cadence_error(hi, &ctx);
  if (!(flo <= 0 && fhi >= 0))
    throw reduced::TableError(fmt::format("no drive torque between {:.4g} and {:.4g} N·m holds {} Hz", lo, hi,
                                          opt.cadence_hz));
  gsl_set_error_handler_off();
  std::unique_ptr<gsl_root_fsolver, decltype(&gsl_root_fsolver_free)> solver(
      gsl_root_fsolver_alloc(gsl_root_fsolver_brent), gsl_root_fsolver_free);
  gsl_root_fsolver_set(solver.get(), &fn, lo, hi);
  double T = r.initial_guess_Nm;
  for (int it = 0; it < 100; ++it) {
    gsl_root_fsolver_iterate(solver.get());
    T = gsl_root_fsolver_root(solver.get());
    progress.count("calibrate: torque search", it + 1, it + 1);
    if (gsl_root_test_interval(gsl_root_fsolver_x_lower(solver.get()), gsl_root_fsolver_x_upper(solver.get()), 0,
                               1e-10) == GSL_SUCCESS)
      break;
  }
  progress.note("");
  r.torque_Nm = T;
  for (auto& t : m.torques) t.value = (t.value < 0 ? -1.0 : 1.0) * T;
  const Cycle cy = steady_cycle(m, scene.initial.q, qd, opt.tolerance, evals, true);
  if (!cy.ok)
    throw models::NumericalError(fmt::format("calibration: the reduced model has no steady cycle at the torque found "
                                             "({:.6g} N·m)", T));
  r.evaluations = evals;
  r.steady_q = scene.initial.q;
  r.steady_qdot = cy.speed;
  r.mean_cadence_hz_reduced = 1.0 / cy.period;
  r.mean_power_w = T * W_unit / cy.period;
  // The result must meet its own target (issue #9): the root finder converges to 1e-10 N·m,
  // so the reduced cadence is off by far less than kReducedCadenceTolerance unless the
  // bracket held a discontinuity (a stall) instead of a root.
  const double miss_reduced = std::abs(r.mean_cadence_hz_reduced - opt.cadence_hz) / opt.cadence_hz;
  if (!(miss_reduced <= kReducedCadenceTolerance))
    throw models::NumericalError(fmt::format(
        "calibration missed its target: the reduced model's steady cadence is {:.6g} Hz at {:.6g} N·m, target {:g} Hz "
        "(off by {:.3g} %, allowed {:g} %)",
        r.mean_cadence_hz_reduced, T, opt.cadence_hz, 100 * miss_reduced, 100 * kReducedCadenceTolerance));

  // Fluctuation and peak force over the steady cycle (sampled and refined by steady_cycle).
  auto fluct = [](const std::vector<double>& v, size_t from) {
    double lo = INFINITY, hi = -INFINITY, sum = 0;
    for (size_t i = from; i < v.size(); ++i) lo = std::min(lo, v[i]), hi = std::max(hi, v[i]), sum += v[i];
    return (hi - lo) / (sum / (v.size() - from));
  };
  r.speed_fluctuation = cy.detail.speed_fluctuation;
  if (!scene.outputs.constraint_forces.empty()) {
    r.force_name = scene.outputs.constraint_forces[0].name;
    r.peak_force_N = cy.detail.peak_force_N[0];
  }

  // Confirmation with the full model from the same point of the steady cycle.
  r.mean_cadence_hz_full = r.speed_fluctuation_full = r.peak_force_full_N = NAN;
  if (!(opt.full_check_s > 0)) {
    r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  }
  progress.note("calibrate: confirming with the full model");
  models::Scene sf = with_loads(scene, T, r.resistance_coefficient);
  sf.initial.q = r.steady_q;
  sf.initial.qdot = r.steady_qdot;
  engine::FullModel full(sf);
  engine::ForwardOptions fo;
  fo.duration_s = opt.full_check_s;
  fo.output_interval_s = 0.002;
  fo.tolerance = 1e-9;
  const auto ts = engine::simulate_full(full, fo);
  // Mean cadence over the whole revolutions after the first second.
  size_t i1 = 0;
  while (i1 < ts.t.size() && ts.t[i1] < 1.0) ++i1;
  r.mean_cadence_hz_full = (ts.q.back() - ts.q[i1]) / (2 * M_PI * (ts.t.back() - ts.t[i1]));
  r.speed_fluctuation_full = fluct(ts.qdot, i1);
  if (!ts.forces.empty()) {
    r.peak_force_full_N = 0.0;
    for (size_t i = i1; i < ts.t.size(); ++i) r.peak_force_full_N = std::max(r.peak_force_full_N, std::abs(ts.forces[0][i]));
  }
  const double miss_full = std::abs(r.mean_cadence_hz_full - opt.cadence_hz) / opt.cadence_hz;
  if (!(miss_full <= kFullCadenceTolerance))
    throw models::NumericalError(fmt::format(
        "calibration not confirmed: the full model at {:.6g} N·m holds a mean cadence of {:.6g} Hz, target {:g} Hz "
        "(off by {:.3g} %, allowed {:g} %)",
        T, r.mean_cadence_hz_full, opt.cadence_hz, 100 * miss_full, 100 * kFullCadenceTolerance));
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

std::string calibrated_scene_yaml(const std::string& source, const std::string& text,
                                  const std::vector<models::Override>& base, const models::Scene& scene,
                                  const CalibrationOptions& opt, const CalibrationResult& r) {
  std::vector<models::Override> o = base;
  auto num = [](double v) { return fmt::format("{:.12g}", v); };
  if (models::scene_yaml_has(text, "bicycle_leg")) {
    // Torques the scene lists under `loads` (profiled hips, say) are scaled there; the
    // generated constant hip torques through hip_torque_Nm, only when the generator made some.
    bool generated = false;
    for (const auto& t : scene.joint_torques) {
      if (!models::scene_yaml_has(text, "loads." + t.name + ".joint")) {
        generated = true;
        continue;
      }
      const std::string key = models::scene_yaml_has(text, "loads." + t.name + ".force_N") ? "force_N" : "torque_Nm";
      o.push_back({"loads." + t.name + "." + key, num((t.value < 0 ? -1 : 1) * r.torque_Nm)});
    }
    if (generated) o.push_back({"bicycle_leg.hip_torque_Nm", num(r.torque_Nm)});
    o.push_back({"bicycle_leg.resistance.power_W", num(opt.power_w)});
    o.push_back({"bicycle_leg.resistance.cadence_Hz", num(opt.cadence_hz)});
  } else {
    for (const auto& t : scene.joint_torques) {
      const std::string key = models::scene_yaml_has(text, "loads." + t.name + ".force_N") ? "force_N" : "torque_Nm";
      o.push_back({"loads." + t.name + "." + key, num((t.value < 0 ? -1 : 1) * r.torque_Nm)});
    }
    const auto& res = scene.resistances[0];
    if (models::scene_yaml_has(text, "loads." + res.name + ".dissipates")) {
      o.push_back({"loads." + res.name + ".dissipates.power_W", num(opt.power_w)});
      o.push_back({"loads." + res.name + ".dissipates.cadence_Hz", num(opt.cadence_hz)});
    } else {
      o.push_back({"loads." + res.name + ".coefficient", num(r.resistance_coefficient)});
    }
  }
  o.push_back({"initial.q", fmt::format("{:.17g}", r.steady_q)});
  o.push_back({"initial.qdot", fmt::format("{:.17g}", r.steady_qdot)});
  const std::string body = models::rewrite_scene_yaml(
      text, scene.source_file, o, {"initial.q", "initial.q_deg", "initial.qdot", "initial.cadence_Hz"});
  // The source name goes into a YAML comment: one line, no control characters (a file name
  // with a newline must not add keys to the scene).
  std::string from;
  for (char c : source) from += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  return fmt::format(
      "# Calibrated by `rdyn calibrate` from {}: drive torque {:.6g} N·m holds a mean cadence of {:.6g} Hz\n"
      "# (reduced) / {:.6g} Hz (full) with the resistance dissipating {:.6g} W at {:.6g} Hz. The initial\n"
      "# conditions are a point of the steady cycle.\n{}",
      from, r.torque_Nm, r.mean_cadence_hz_reduced, r.mean_cadence_hz_full, opt.power_w, opt.cadence_hz, body);
}

}  // namespace rdyn::validate
