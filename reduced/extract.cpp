#include "reduced/extract.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_spline.h>

namespace rdyn::reduced {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Revolute joints from ground to a body: in the plane, the body's angular rate is the sum
// of their rates.
std::vector<int> revolute_path(const models::Scene& s, const std::string& body) {
  std::vector<int> path;
  std::string cur = body;
  while (cur != models::kGround) {
    for (size_t j = 0; j < s.joints.size(); ++j) {
      if (s.joints[j].child != cur) continue;
      if (s.joints[j].type == models::JointType::Revolute) path.push_back(static_cast<int>(j));
      cur = s.joints[j].parent;
      break;
    }
  }
  return path;
}

// GSL periodic cubic spline through (q, y) over one period (the first point repeated at
// q[0] + period, as GSL's periodic splines require).
struct PeriodicSpline {
  std::vector<double> x, y;
  std::unique_ptr<gsl_spline, decltype(&gsl_spline_free)> sp{nullptr, gsl_spline_free};
  PeriodicSpline(const std::vector<double>& q, const std::vector<double>& v, double period) : x(q), y(v) {
    x.push_back(q[0] + period);
    y.push_back(v[0]);
    sp.reset(gsl_spline_alloc(gsl_interp_cspline_periodic, x.size()));
    gsl_spline_init(sp.get(), x.data(), y.data(), x.size());
  }
  double eval(double q) const {  // q wrapped into [x.front(), x.back()]
    const double P = x.back() - x.front();
    return gsl_spline_eval(sp.get(), q - P * std::floor((q - x.front()) / P), nullptr);
  }
};

// ∫ from q[0] to q[i] of a periodic cubic spline through (q, y), for every grid point.
std::vector<double> periodic_integral(const std::vector<double>& q, const std::vector<double>& y, double period) {
  const PeriodicSpline sp(q, y, period);
  std::vector<double> out(q.size());
  for (size_t i = 0; i < q.size(); ++i) out[i] = gsl_spline_eval_integ(sp.sp.get(), sp.x[0], sp.x[i], nullptr);
  return out;
}

struct RatioRootContext {
  KinetostaticSource* src;
  int joint;
};

double ratio_at(double q, void* p) {
  auto* c = static_cast<RatioRootContext*>(p);
  return c->src->ratio(q, c->joint);
}

// Zeros of joint j's velocity ratio over one period, located on the full model: each sign
// change between grid samples is first located on the periodic cubic spline of the samples,
// then bracketed tightly around that estimate on the full model and refined with Brent's
// method (GSL). A pair of zeros inside one grid interval is not seen: refine the grid if a
// gate switches that quickly.
std::vector<double> ratio_roots(KinetostaticSource& src, int j, const std::vector<double>& q,
                                const std::vector<double>& r, double period) {
  std::vector<double> roots;
  const size_t n = q.size();
  const PeriodicSpline sp(q, r, period);
  const auto& x = sp.x;
  const auto& y = sp.y;
  std::unique_ptr<gsl_root_fsolver, decltype(&gsl_root_fsolver_free)> solver(
      gsl_root_fsolver_alloc(gsl_root_fsolver_brent), gsl_root_fsolver_free);
  RatioRootContext ctx{&src, j};
  gsl_function fn{ratio_at, &ctx};
  auto brent = [&](double a, double b) {
    gsl_root_fsolver_set(solver.get(), &fn, a, b);
    double root = 0.5 * (a + b);
    for (int it = 0; it < 100; ++it) {
      if (gsl_root_fsolver_iterate(solver.get()) != GSL_SUCCESS) break;
      root = gsl_root_fsolver_root(solver.get());
      if (gsl_root_test_interval(gsl_root_fsolver_x_lower(solver.get()), gsl_root_fsolver_x_upper(solver.get()),
                                 1e-14, 0.0) == GSL_SUCCESS)
        break;
    }
    return root;
  };
  for (size_t i = 0; i < n; ++i) {
    const double a = x[i], b = x[i + 1], ra = y[i], rb = y[i + 1];
    if (ra == 0.0) {
      roots.push_back(a);
      continue;
    }
    if ((ra > 0) == (rb > 0) || rb == 0.0) continue;
    // Estimate on the spline (bisection: no full-model calls).
    double lo = a, hi = b;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      ((sp.eval(mid) > 0) == (ra > 0) ? lo : hi) = mid;
    }
    const double est = 0.5 * (lo + hi);
    // Tight bracket on the full model, widened until the sign changes (within the interval).
    double w = 1e-3 * (b - a), root = NAN;
    for (int k = 0; k < 12 && std::isnan(root); ++k, w *= 4) {
      const double l = std::max(a, est - w), h = std::min(b, est + w);
      const double fl = l == a ? ra : src.ratio(l, j), fh = h == b ? rb : src.ratio(h, j);
      if (fl == 0.0) root = l;
      else if (fh == 0.0) root = h;
      else if ((fl > 0) != (fh > 0)) root = brent(l, h);
    }
    roots.push_back(std::isnan(root) ? brent(a, b) : root);
  }
  return roots;
}

}  // namespace

Method parse_method(const std::string& name) {
  if (name == "kinetostatic") return Method::Kinetostatic;
  if (name == "paper-sweep") return Method::PaperSweep;
  if (name == "integrated") return Method::Integrated;
  if (name == "direct") return Method::Direct;
  throw TableError("unknown extraction method '" + name + "' (kinetostatic, paper-sweep, integrated, direct)");
}

std::string method_name(Method m) {
  switch (m) {
    case Method::Kinetostatic: return "kinetostatic";
    case Method::PaperSweep: return "paper-sweep";
    case Method::Integrated: return "integrated";
    case Method::Direct: return "direct";
  }
  return "?";
}

Samples extract_samples(KinetostaticSource& src, const models::Scene& scene, const ExtractOptions& opt) {
  const auto& ind = *scene.find_joint(scene.independent);
  if (ind.type != models::JointType::Revolute)
    throw TableError("reduced tables over a range of a prismatic coordinate are not supported yet; "
                     "the independent coordinate must be a revolute joint turning fully");
  const double n_real = 2 * kPi / opt.step_rad;
  const long n = std::lround(n_real);
  if (!(opt.step_rad > 0) || n < 4 || std::abs(n_real - n) > 1e-6)
    throw TableError(fmt::format("grid step {:.6g}° must divide 360° into at least 4 parts",
                                 opt.step_rad * 180 / kPi));
  const double h = 2 * kPi / n;
  const int nk = src.num_constraint_forces(), nj = src.num_joints();
  const auto& forces = scene.outputs.constraint_forces;

  // Grid anchored at 0, visited from the point nearest the initial q.
  const long first = std::lround(scene.initial.q / h);
  Samples s;
  s.scene = scene.name;
  s.method = method_name(opt.method);
  s.periodic = true;
  s.revolute = true;
  s.step = h;
  for (long i = 0; i < n; ++i) s.q.push_back((first + i) * h);
  s.q0 = s.q[0];

  std::vector<double> m1(n), m2(n), Q(n), V(n);
  std::vector<std::vector<double>> me1(nk, std::vector<double>(n)), me2 = me1, Qx = me1;
  std::vector<std::vector<double>> r(nj, std::vector<double>(n));
  std::vector<std::vector<std::vector<double>>> rx(nk, r);

  // Inertial parameters.
  if (opt.method == Method::PaperSweep) {
    // (i) constant speed: q(t) = q_first + ω t sampled at t_i = i h/ω (q̈ = 0).
    const double w = 1.0;
    const double lin[5] = {s.q0, w, 0.0, 0.0, 0.0};
    for (long i = 0; i < n; ++i) {
      const auto p = src.harmonic_sweep(lin, i * h / w);
      if (!p) throw TableError("this source cannot run prescribed-motion sweeps");
      m2[i] = p->driving_force / (w * w);
      for (int k = 0; k < nk; ++k) me2[k][i] = p->constraint_forces[k] / (w * w);
    }
    // (ii) the paper's law q(t) = c1 + c2 t + c3 cos(c4 t + c5), one oscillation per grid
    // interval (c4 = 2π/τ, τ = 1 s, c2 = h/τ) with c5 = π/4 and c3 = c2/(c4 sin c5), so that at
    // t_i = iτ: q = q_i, q̇ = c2 − c3 c4 sin c5 = 0 and q̈ = −c3 c4² cos c5 = −c2 c4 ≠ 0.
    const double tau = 1.0, c2 = h / tau, c4 = 2 * kPi / tau, c5 = kPi / 4, c3 = c2 / (c4 * std::sin(c5));
    const double c1 = s.q0 - c3 * std::cos(c5);
    const double law[5] = {c1, c2, c3, c4, c5};
    const double qdd = -c3 * c4 * c4 * std::cos(c5);
    for (long i = 0; i < n; ++i) {
      const auto p = src.harmonic_sweep(law, i * tau);
      m1[i] = p->driving_force / qdd;
      for (int k = 0; k < nk; ++k) me1[k][i] = p->constraint_forces[k] / qdd;
    }
  } else if (opt.method == Method::Direct) {
    for (long i = 0; i < n; ++i) {
      const auto d = src.direct(s.q[i]);
      if (!d) throw TableError("this source cannot compute the direct (mass-matrix) route");
      m1[i] = d->m1;
      m2[i] = d->m2;
      for (int k = 0; k < nk; ++k) me1[k][i] = d->me1[k], me2[k][i] = d->me2[k];
    }
  }

  // One visit per grid point: (i) and (ii) when the method needs them, the static call for
  // position-only loads (only when the scene has some), and the velocity ratios.
  const bool conservative_loads = scene.gravity.enabled || !scene.springs.empty();
  const bool inertial_here = opt.method == Method::Kinetostatic || opt.method == Method::Integrated;
  std::vector<char> singular(n, 0);
  for (long i = 0; i < n; ++i) {
    GridSample g;
    if (inertial_here) {
      g = src.sample(s.q[i], conservative_loads);
      m2[i] = g.velocity.driving_force;      // (i) q̇ = 1, q̈ = 0
      m1[i] = g.acceleration.driving_force;  // (ii) q̇ = 0, q̈ = 1
      for (int k = 0; k < nk; ++k)
        me2[k][i] = g.velocity.constraint_forces[k], me1[k][i] = g.acceleration.constraint_forces[k];
    } else {
      if (conservative_loads) g.conservative = src.conservative(s.q[i]);
      else g.conservative.forces.constraint_forces.assign(nk, 0.0);
      g.ratios = src.ratios(s.q[i]);
    }
    // At rest: T_act + Q = 0 and F_E + Qx = 0.
    Q[i] = -g.conservative.forces.driving_force;
    V[i] = g.conservative.potential_energy;
    for (int k = 0; k < nk; ++k) Qx[k][i] = -g.conservative.forces.constraint_forces[k];
    for (int j = 0; j < nj; ++j) {
      r[j][i] = g.ratios.wrt_q[j];
      for (int k = 0; k < nk; ++k) rx[k][j][i] = g.ratios.wrt_x[k][j];
    }
    singular[i] = g.singular;
  }
  if (opt.method == Method::Integrated) {
    // m1(q) = m1(q_first) + ∫ dm1/dq dq with dm1/dq = 2 m2 (Eksergian: m2 = ½ dm1/dq).
    std::vector<double> two_m2(n);
    for (long i = 0; i < n; ++i) two_m2[i] = 2 * m2[i];
    const auto integral = periodic_integral(s.q, two_m2, 2 * kPi);
    for (long i = 1; i < n; ++i) m1[i] = m1[0] + integral[i];
  }

  // Samples at singular configurations (loop Jacobian lost rank) carry velocities the
  // constraints do not determine: replace every column there by a periodic cubic spline
  // through the regular samples, i.e. the limit along the branch the sweep follows.
  auto repair = [&](std::vector<double>& col) {
    std::vector<double> x, y;
    for (long i = 0; i < n; ++i)
      if (!singular[i]) x.push_back(s.q[i]), y.push_back(col[i]);
    if (x.size() < 4 || x.size() == static_cast<size_t>(n)) return;
    const PeriodicSpline sp(x, y, 2 * kPi);
    for (long i = 0; i < n; ++i)
      if (singular[i]) col[i] = sp.eval(s.q[i]);
  };
  if (std::count(singular.begin(), singular.end(), 1) > 0) {
    for (long i = 0; i < n; ++i)
      if (singular[i]) s.singular_q.push_back(s.q[i]);
    for (auto* col : {&m1, &m2, &Q, &V}) repair(*col);
    for (int k = 0; k < nk; ++k) repair(me1[k]), repair(me2[k]), repair(Qx[k]);
    for (int j = 0; j < nj; ++j) {
      repair(r[j]);
      for (int k = 0; k < nk; ++k) repair(rx[k][j]);
    }
  }

  s.add("m1", m1);
  s.add("m2", m2);
  for (int k = 0; k < nk; ++k) {
    s.add("me1_" + forces[k].name, me1[k]);
    s.add("me2_" + forces[k].name, me2[k]);
  }
  s.add("Q_cons", Q);
  s.add("V", V);
  for (int k = 0; k < nk; ++k) s.add("Qx_cons_" + forces[k].name, Qx[k]);
  for (int j = 0; j < nj; ++j) s.add("r_" + scene.joints[j].name, r[j]);
  for (int k = 0; k < nk; ++k)
    for (int j = 0; j < nj; ++j) s.add("rx_" + forces[k].name + "_" + scene.joints[j].name, rx[k][j]);
  // Switch angles of rate-gated loads: exact zeros of the gating joint's ratio.
  gsl_set_error_handler_off();
  for (const auto& t : scene.joint_torques) {
    if (!t.active_when) continue;
    const std::string col = "r_" + t.active_when->joint;
    if (s.roots_of(col)) continue;
    const int j = scene.joint_index(t.active_when->joint);
    s.roots.emplace_back(col, ratio_roots(src, j, s.q, r[j], 2 * kPi));
  }
  // Body angular rates for the bodies that carry a resistance.
  for (const auto& res : scene.resistances) {
    if (s.column("w_" + res.body) >= 0) continue;
    const auto path = revolute_path(scene, res.body);
    std::vector<double> w(n, 0.0);
    std::vector<std::vector<double>> wx(nk, std::vector<double>(n, 0.0));
    for (int j : path)
      for (long i = 0; i < n; ++i) {
        w[i] += r[j][i];
        for (int k = 0; k < nk; ++k) wx[k][i] += rx[k][j][i];
      }
    s.add("w_" + res.body, w);
    for (int k = 0; k < nk; ++k) s.add("wx_" + forces[k].name + "_" + res.body, wx[k]);
  }
  return s;
}

}  // namespace rdyn::reduced
