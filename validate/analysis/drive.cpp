#include "validate/analysis/drive.hpp"

#include "reduced/sweep_refine.hpp"

#include "reduced/joint_outputs.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_spline.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <memory>
#include <iterator>
#include <sstream>

#include <fmt/format.h>

#include "engine/full_model.hpp"
#include "engine/independent_range.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/samples.hpp"

namespace rdyn::validate {

namespace {

using Clock = std::chrono::steady_clock;

// Output times 0, dt, 2dt, … and the duration itself as the last row.
std::vector<double> output_times(double duration_s, double dt_s) {
  std::vector<double> t;
  const long n = static_cast<long>(std::floor(duration_s / dt_s + 1e-9));
  for (long i = 0; i <= n; ++i) t.push_back(std::min(duration_s, i * dt_s));
  if (duration_s - t.back() > 1e-9 * duration_s) t.push_back(duration_s);
  return t;
}

DriveRecord start_record(const PrescribedMotion& m, std::vector<std::string> force_names) {
  DriveRecord r;
  r.t = m.t, r.q = m.q, r.qdot = m.qdot, r.qddot = m.qddot;
  r.force_names = std::move(force_names);
  r.forces.assign(r.force_names.size(), {});
  return r;
}

void check_finite(double v, const char* what, double t) {
  if (!std::isfinite(v))
    throw models::NumericalError(fmt::format("the drive's {} is not finite at t = {:.6g} s", what, t));
}

}  // namespace

double calc_drive_moves(const PrescribedMotion& m) {
  double path = 0.0;
  for (size_t i = 1; i < m.q.size(); ++i) path += std::abs(m.q[i] - m.q[i - 1]);
  return path / kDriveMove + static_cast<double>(m.q.size());
}

PrescribedMotion constant_rate_motion(double q0, double rate, double duration_s, double dt_s) {
  PrescribedMotion m;
  m.t = output_times(duration_s, dt_s);
  for (double t : m.t) {
    m.q.push_back(q0 + rate * t);
    m.qdot.push_back(rate);
    m.qddot.push_back(0.0);
  }
  return m;
}

PrescribedMotion revolution_motion(double q0, double cadence_hz) {
  const double period = 1.0 / std::abs(cadence_hz);
  PrescribedMotion m = constant_rate_motion(q0, 2 * M_PI * cadence_hz, period, period / 360);
  m.how = fmt::format("constant rate {:g} rev/s from q = {:g}°, one revolution", cadence_hz, q0 * 180 / M_PI);
  return m;
}

PrescribedMotion profile_motion(const std::string& path, bool revolute, std::optional<double> duration_opt, double dt_s,
                                double max_rows) {
  // Checked before opening: a FIFO without a writer would block, a device never ends.
  if (const std::string kind = models::non_regular_file_kind(path); !kind.empty())
    throw models::SceneError(path, 0, "--profile", "not a regular file (" + kind + "): give a CSV file t,q_deg or t,q_m");
  std::ifstream file(path, std::ios::binary);
  if (!file) throw models::SceneError(path, 0, "--profile", "cannot be read");
  // An editor's byte-order mark and CR-only line ends change no value (as for tables).
  std::istringstream in(models::normalise_text_encoding(
      std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>())));
  bool header_seen = false;
  auto quoted = [](const std::string& l) { return l.size() > 60 ? l.substr(0, 60) + "…" : l; };
  std::string line;
  int line_no = 0;
  std::vector<double> t, q;
  const std::string want = revolute ? "t,q_deg" : "t,q_m";
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (!header_seen) {  // the first line that is not a comment
      if (line != want)
        throw models::SceneError(path, line_no, "header",
                                 fmt::format("the header must be '{}' (the independent coordinate is {}), got '{}'",
                                             want, revolute ? "revolute: degrees" : "prismatic: metres", quoted(line)));
      header_seen = true;
      continue;
    }
    std::istringstream row(line);
    std::string a, b, extra;
    if (!std::getline(row, a, ',') || !std::getline(row, b, ',') || std::getline(row, extra, ','))
      throw models::SceneError(path, line_no, "row", "a row must hold two numbers: t,q");
    double tv = NAN, qv = NAN;
    try {
      size_t ea = 0, eb = 0;
      tv = std::stod(a, &ea), qv = std::stod(b, &eb);
      if (a.find_first_not_of(' ', ea) != std::string::npos || b.find_first_not_of(' ', eb) != std::string::npos)
        throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      throw models::SceneError(path, line_no, "row", fmt::format("'{}' is not two decimal numbers", quoted(line)));
    }
    if (!std::isfinite(tv) || !std::isfinite(qv) || std::abs(qv) > 1e7)
      throw models::SceneError(path, line_no, "row", "t and q must be finite (|q| ≤ 1e7)");
    if (!t.empty() && !(tv > t.back()))
      throw models::SceneError(path, line_no, "t", fmt::format("times must increase ({:g} after {:g})", tv, t.back()));
    // Rows closer than 1 µs make the spline's q̇ and q̈ overflow (1e-300 s apart: "non-finite
    // value prescribed", exit 1): bad input, said on its line.
    if (!t.empty() && tv - t.back() < kMinProfileStep_s)
      throw models::SceneError(path, line_no, "t",
                               fmt::format("rows must be at least {:g} s apart ({:g} after {:g})", kMinProfileStep_s, tv,
                                           t.back()));
    if (t.size() >= 1000000) throw models::SceneError(path, line_no, "row", "more than 1e6 rows");
    t.push_back(tv);
    q.push_back(revolute ? qv * M_PI / 180 : qv);
  }
  if (t.size() < 4) throw models::SceneError(path, line_no, "rows", "a profile needs at least 4 rows");
  const double span = t.back() - t.front();
  const double duration_s = duration_opt.value_or(span);
  if (!(duration_s / dt_s <= max_rows))
    throw models::SceneError(path, 0, "--dt-out", fmt::format("{:g} s over {:g} s makes too many rows", dt_s, duration_s));
  if (!(duration_s <= span * (1 + 1e-12)))
    throw models::SceneError(path, 0, "--duration",
                             fmt::format("{:g} s is longer than the profile's {:g} s", duration_s, span));
  // Natural cubic spline through the profile: C² so q̈ is continuous (docs/theory.md).
  gsl_error_handler_t* old = gsl_set_error_handler_off();
  std::unique_ptr<gsl_interp_accel, void (*)(gsl_interp_accel*)> acc(gsl_interp_accel_alloc(), gsl_interp_accel_free);
  std::unique_ptr<gsl_spline, void (*)(gsl_spline*)> sp(gsl_spline_alloc(gsl_interp_cspline, t.size()),
                                                         gsl_spline_free);
  const int status = gsl_spline_init(sp.get(), t.data(), q.data(), t.size());
  gsl_set_error_handler(old);
  if (status) throw models::SceneError(path, 0, "rows", "the profile cannot be interpolated");
  PrescribedMotion m;
  m.t = output_times(duration_s, dt_s);
  for (double& tt : m.t) {
    const double x = std::min(t.back(), t.front() + tt);
    m.q.push_back(gsl_spline_eval(sp.get(), x, acc.get()));
    m.qdot.push_back(gsl_spline_eval_deriv(sp.get(), x, acc.get()));
    m.qddot.push_back(gsl_spline_eval_deriv2(sp.get(), x, acc.get()));
  }
  return m;
}

namespace {

// A value with a pole at a singular configuration (f ≈ a/(q − q_s): an isosceles slider-crank's
// rod force where it folds) has no limit there: the symmetric one is its principal value, finite
// and wrong. Refused (exit 1) as the reduced model refuses its band (reduced::check_force_poles),
// from the kinetostatic results at q_s − δ, q_s − δ/2, q_s + δ/2, q_s + δ. `between`: words for a
// configuration between two output rows.
void refuse_poles(const models::Scene& scene, const std::vector<engine::KinetostaticResult>& side, double t, double q,
                  const std::string& between) {
  const bool revolute = scene.find_joint(scene.independent)->type == models::JointType::Revolute;
  auto refuse = [&](const std::string& what, double m1, double m2, double p2, double p1) {
    if (!reduced::is_simple_pole(m1, m2, p2, p1)) return;
    throw models::NumericalError(fmt::format(
        "the full model's {} grows without bound at t = {:.6g} s ({} = {:.9g}{}{}): the prescribed motion passes a "
        "singular configuration where the loop Jacobian loses rank, and there it has a pole (≈ a/(q − q_s)), so no "
        "finite value exists; prescribe a motion that stops short of it, or leave that output out",
        what, t, scene.independent, revolute ? q * 180 / M_PI : q, revolute ? "°" : " m", between));
  };
  refuse("drive", side[0].driving_force, side[1].driving_force, side[2].driving_force, side[3].driving_force);
  for (size_t c = 0; c < scene.outputs.constraint_forces.size(); ++c)
    refuse("constraint force '" + scene.outputs.constraint_forces[c].name + "'", side[0].constraint_forces[c],
           side[1].constraint_forces[c], side[2].constraint_forces[c], side[3].constraint_forces[c]);
}

// The singular configurations (engine::calc_independent_domain's scan; every turn's image for a
// full turn) strictly between q_a and q_b [rad or m], in the order the motion meets them.
std::vector<double> singular_between(const std::vector<engine::SingularPoint>& singular, bool periodic, double q_a,
                                     double q_b) {
  std::vector<double> out;
  const double lo = std::min(q_a, q_b), hi = std::max(q_a, q_b), tol = 1e-9 * std::max(1.0, hi - lo);
  for (const auto& sp : singular) {
    const double turn = 2 * M_PI;
    const double first = periodic ? sp.q + turn * std::ceil((lo - sp.q) / turn) : sp.q;
    for (double qs = first; qs < hi - tol; qs += turn) {
      if (qs > lo + tol) out.push_back(qs);
      if (!periodic) break;
    }
  }
  std::sort(out.begin(), out.end());
  if (q_b < q_a) std::reverse(out.begin(), out.end());
  return out;
}

}  // namespace

DriveRecord calc_drive_full(const models::Scene& scene, const PrescribedMotion& motion) {
  const auto start = Clock::now();
  std::vector<std::string> names;
  for (const auto& f : scene.outputs.constraint_forces) names.push_back(f.name);
  DriveRecord r = start_record(motion, names);
  const engine::FullModel model(scene);
  engine::FullWorkspace ws(model);
  // The configuration follows q along its branch as the extraction's sweep does (second-order
  // predictor, the chord through singular configurations), in moves of at most kMove: a plain
  // projection from the previous row switched a parallelogram to its antiparallelogram at 3.6°
  // rows through the aligned position.
  double q_prev = motion.q.empty() ? 0.0 : motion.q[0];
  auto follow = [&](double q_to) {
    const int moves = std::max(1, static_cast<int>(std::ceil(std::abs(q_to - q_prev) / kDriveMove)));
    for (int k = 1; k <= moves; ++k)
      engine::calc_kinetostatic_sample(model, ws, q_prev + (q_to - q_prev) * k / moves, 2 * kDriveMove,
                                       engine::SampleParts::All);
    q_prev = q_to;
  };
  // Inverse dynamics at q: the driver's generalized force T_act with every load applied.
  auto inverse = [&](double q, size_t i) {
    return engine::calc_kinetostatic(model, ws, q, motion.qdot[i], motion.qddot[i], engine::Loads::All);
  };
  const bool revolute = scene.find_joint(scene.independent)->type == models::JointType::Revolute;
  // A fold the rows step over: its pole shows on no row, and the rows' peak depended on --dt-out
  // (the isosceles slider-crank's rod force 21.6 N at 3 ms rows, 71.8 N at 0.7 ms). The scan's
  // singular configurations between two rows are checked at q̇, q̈ interpolated there.
  const auto domain = engine::calc_independent_domain(model);
  auto check_between_rows = [&](size_t i) {
    for (double qs : singular_between(domain.singular, domain.periodic, motion.q[i - 1], motion.q[i])) {
      const double f = (qs - motion.q[i - 1]) / (motion.q[i] - motion.q[i - 1]);
      auto at = [&](const std::vector<double>& v) { return v[i - 1] + f * (v[i] - v[i - 1]); };
      const double d = (revolute ? 1e-2 : 1e-3) * (motion.q[i] > motion.q[i - 1] ? 1 : -1);
      std::vector<engine::KinetostaticResult> side;
      for (double off : {-d, -d / 2, d / 2, d}) {
        follow(qs + off);
        side.push_back(engine::calc_kinetostatic(model, ws, qs + off, at(motion.qdot), at(motion.qddot),
                                                 engine::Loads::All));
      }
      if (d < 0) std::reverse(side.begin(), side.end());  // q_s − δ first
      refuse_poles(scene, side, at(motion.t), qs, ", between two output rows");
    }
  };
  const bool joint_outputs = reduced::wants_joint_outputs(scene);
  if (joint_outputs) {
    r.column_names = models::joint_output_names(scene);
    r.columns.assign(r.column_names.size(), {});
  }
  for (size_t i = 0; i < motion.t.size(); ++i) {
    if (std::chrono::duration<double>(Clock::now() - start).count() > kDriveMaxWall_s)
      throw models::NumericalError(fmt::format("the full model's drive stopped at t = {:.6g} s: it used its wall-time "
                                               "budget of {:g} s",
                                               motion.t[i], kDriveMaxWall_s));
    try {
      if (i > 0) check_between_rows(i);
      follow(motion.q[i]);
    } catch (const engine::EngineError&) {
      // Simbody's projection text says nothing a user can act on: the motion asks for a
      // configuration the mechanism does not have.
      throw engine::EngineError(fmt::format(
          "{}: the prescribed motion reaches {} = {:.9g}{} at t = {:.6g} s, where the mechanism cannot be assembled "
          "(past a dead point or the end of its range, or a loop that cannot close there); keep the motion inside "
          "the range `rdyn inspect` reports",
          scene.source_file, scene.independent, revolute ? motion.q[i] * 180 / M_PI : motion.q[i],
          revolute ? "°" : " m", motion.t[i]));
    }
    // At a singular configuration the velocity projection itself may fail (a profile starting on
    // an isosceles slider-crank's folded position): nothing is asked of the model there but the
    // limits below.
    const bool singular = engine::calc_loop_conditioning(model, ws) < engine::kSingularConditioning;
    engine::KinetostaticResult k;
    std::vector<double> cols;
    if (!singular) {
      k = inverse(motion.q[i], i);
      if (joint_outputs) cols = engine::calc_joint_output_row(model, ws);
    }
    if (singular) {
      // At a singular configuration the constraint forces (and with them T_act) are a
      // least-squares split of no branch (a parallelogram's drive came out 0.31 k for k): the
      // limit along the branch from both sides, as the extraction's singular samples
      // (Richardson on q ± δ/2, q ± δ; reduced/extract.cpp).
      const double d = revolute ? 1e-2 : 1e-3;
      std::vector<engine::KinetostaticResult> side;
      std::vector<std::vector<double>> side_cols;
      for (double off : {-d, -d / 2, d / 2, d}) {
        follow(motion.q[i] + off);
        side.push_back(inverse(motion.q[i] + off, i));
        if (joint_outputs) side_cols.push_back(engine::calc_joint_output_row(model, ws));
      }
      auto limit = [](double m1, double m2, double p2, double p1) { return (2 * (m2 + p2) - 0.5 * (m1 + p1)) / 3; };
      refuse_poles(scene, side, motion.t[i], motion.q[i], "");
      k = side[0];
      if (joint_outputs) cols.assign(side_cols[0].size(), 0.0);
      for (size_t c = 0; c < cols.size(); ++c)
        cols[c] = limit(side_cols[0][c], side_cols[1][c], side_cols[2][c], side_cols[3][c]);
      k.driving_force = limit(side[0].driving_force, side[1].driving_force, side[2].driving_force,
                              side[3].driving_force);
      for (size_t c = 0; c < names.size(); ++c)
        k.constraint_forces[c] = limit(side[0].constraint_forces[c], side[1].constraint_forces[c],
                                       side[2].constraint_forces[c], side[3].constraint_forces[c]);
    }
    check_finite(k.driving_force, "generalized force", motion.t[i]);
    r.drive.push_back(k.driving_force);
    r.power.push_back(k.driving_force * motion.qdot[i]);
    for (size_t c = 0; c < names.size(); ++c) {
      check_finite(k.constraint_forces[c], "constraint force", motion.t[i]);
      r.forces[c].push_back(k.constraint_forces[c]);
    }
    for (size_t c = 0; c < cols.size(); ++c) {
      check_finite(cols[c], "joint output", motion.t[i]);
      r.columns[c].push_back(cols[c]);
    }
  }
  r.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

DriveRecord calc_drive_reduced(const reduced::ReducedModel& model, const PrescribedMotion& motion) {
  const auto start = Clock::now();
  DriveRecord r = start_record(motion, model.force_names);
  reduced::ReducedWorkspace ws(model);
  std::vector<double> f(model.force_names.size());
  for (size_t i = 0; i < motion.t.size(); ++i) {
    if (!model.table.in_range(motion.q[i]))
      throw reduced::TableError(fmt::format("the prescribed motion leaves the table's range at t = {:.6g} s (q = "
                                            "{:.6g}): prescribe a motion inside the mechanism's range",
                                            motion.t[i], motion.q[i]));
    reduced::check_force_poles(model, motion.q[i], motion.t[i]);
    double power_nc = 0.0;
    const double d = reduced::calc_drive(model, ws, motion.q[i], motion.qdot[i], motion.qddot[i], power_nc, f.data());
    check_finite(d, "generalized force", motion.t[i]);
    r.drive.push_back(d);
    r.power.push_back(d * motion.qdot[i]);
    for (size_t c = 0; c < f.size(); ++c) {
      check_finite(f[c], "constraint force", motion.t[i]);
      r.forces[c].push_back(f[c]);
    }
  }
  r.wall_s = std::chrono::duration<double>(Clock::now() - start).count();
  return r;
}

DriveRecord calc_drive_reduced(const models::Scene& scene, const reduced::ReducedModel& model,
                               const PrescribedMotion& motion) {
  DriveRecord r = calc_drive_reduced(model, motion);
  if (!reduced::wants_joint_outputs(scene)) return r;
  // The rows as a reduced run, so the joint outputs come from the one implementation
  // (reduced::add_joint_outputs), which also drops the internal constraint lines.
  models::TimeSeries ts;
  ts.force_names = r.force_names;
  ts.t = r.t, ts.q = r.q, ts.qdot = r.qdot, ts.qddot = r.qddot;
  ts.forces = r.forces;
  reduced::add_joint_outputs(scene, model, ts);
  r.force_names = ts.force_names;
  r.forces = ts.forces;
  r.column_names = ts.column_names;
  r.columns = ts.columns;
  return r;
}

std::vector<std::string> drive_column_names(const std::vector<std::string>& force_names,
                                            const std::vector<std::string>& column_names, bool revolute) {
  std::vector<std::string> names{"t", "q", "qdot", "qddot", revolute ? "drive_Nm" : "drive_N", "drive_W"};
  for (const auto& n : force_names) names.push_back("F_" + n);  // names are checked by the scene reader
  names.insert(names.end(), column_names.begin(), column_names.end());
  return names;
}

std::vector<std::string> drive_column_names(const DriveRecord& r, bool revolute) {
  return drive_column_names(r.force_names, r.column_names, revolute);
}

const std::vector<double>& drive_column(const DriveRecord& r, size_t k) {
  const std::vector<double>* fixed[] = {&r.t, &r.q, &r.qdot, &r.qddot, &r.drive, &r.power};
  if (k < 6) return *fixed[k];
  return k - 6 < r.forces.size() ? r.forces[k - 6] : r.columns[k - 6 - r.forces.size()];
}

DriveStats calc_drive_stats(const DriveRecord& r) {
  DriveStats s;
  const size_t n = r.drive.size();
  if (n == 0) return s;
  // Time averages by the trapezoidal rule over the rows (uneven last row included).
  double sum = 0, sum2 = 0, sum_p = 0;
  for (size_t i = 0; i + 1 < n; ++i) {
    const double h = r.t[i + 1] - r.t[i];
    sum += 0.5 * h * (r.drive[i] + r.drive[i + 1]);
    sum2 += 0.5 * h * (r.drive[i] * r.drive[i] + r.drive[i + 1] * r.drive[i + 1]);
    sum_p += 0.5 * h * (r.power[i] + r.power[i + 1]);
  }
  const double T = r.t.back() - r.t.front();
  s.mean = T > 0 ? sum / T : r.drive[0];
  s.rms = T > 0 ? std::sqrt(sum2 / T) : std::abs(r.drive[0]);
  s.mean_power_W = T > 0 ? sum_p / T : r.power[0];
  for (size_t i = 0; i < n; ++i) {
    s.peak = std::max(s.peak, std::abs(r.drive[i]));
    s.peak_power_W = std::max(s.peak_power_W, r.power[i]);
  }
  for (const auto& col : r.forces) {
    double p = 0;
    for (double v : col) p = std::max(p, std::abs(v));
    s.force_peaks.push_back(p);
  }
  return s;
}

MotorCheck calc_motor_check(const DriveRecord& r, double stall, double no_load_speed) {
  MotorCheck c;
  c.stall = stall, c.no_load_speed = no_load_speed;
  const double sign = stall > 0 ? 1.0 : -1.0;
  c.min_margin = INFINITY;
  for (size_t i = 0; i < r.drive.size(); ++i) {
    const double line = models::motor_torque(stall, no_load_speed, r.qdot[i]);
    const double margin = sign * (line - r.drive[i]);
    if (margin < c.min_margin) {
      c.min_margin = margin, c.at_t = r.t[i], c.at_q = r.q[i];
      c.drive_there = r.drive[i], c.line_there = line;
    }
  }
  c.covers = c.min_margin >= 0;
  c.min_margin_fraction = c.min_margin / std::abs(stall);
  return c;
}

DriveCycleComparison calc_drive_cycle_comparison(const models::Scene& scene, const reduced::ReducedModel& model,
                                                 double cadence_hz) {
  DriveCycleComparison c;
  c.cadence_hz = cadence_hz;
  c.q0 = scene.initial.q;
  const PrescribedMotion motion = revolution_motion(c.q0, cadence_hz);
  c.full = calc_drive_full(scene, motion);
  c.reduced = calc_drive_reduced(model, motion);
  c.full_stats = calc_drive_stats(c.full);
  c.reduced_stats = calc_drive_stats(c.reduced);
  // The difference's RMS over time by the trapezoidal rule, as calc_drive_stats's RMS.
  DriveRecord diff;
  diff.t = motion.t;
  for (size_t i = 0; i < motion.t.size(); ++i) {
    const double d = c.reduced.drive[i] - c.full.drive[i];
    diff.drive.push_back(d);
    diff.power.push_back(0.0);
    c.max_difference = std::max(c.max_difference, std::abs(d));
  }
  c.rms_difference = calc_drive_stats(diff).rms;
  return c;
}

}  // namespace rdyn::validate
