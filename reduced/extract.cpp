#include "reduced/extract.hpp"

#include "models/gear_fold.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>

#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_spline.h>

#include "models/scene_hash.hpp"
#include "reduced/sweep_refine.hpp"
#include "reduced/table.hpp"
#include "reduced/joint_outputs.hpp"

namespace rdyn::reduced {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Revolute joints from ground to a body: in the plane, the body's angular rate is the sum
// of their rates.
std::vector<int> revolute_path(const models::Scene& s, const std::string& body) {
  std::vector<int> path;
  std::string cur = body;
  // A checked scene is a tree, so ground is reached in at most one hop per joint.
  for (size_t hops = 0; cur != models::kGround; ++hops) {
    if (hops > s.joints.size()) throw TableError("body '" + body + "' is not connected to ground by joints");
    bool found = false;
    for (size_t j = 0; j < s.joints.size() && !found; ++j) {
      if (s.joints[j].child != cur) continue;
      if (s.joints[j].type == models::JointType::Revolute) path.push_back(static_cast<int>(j));
      cur = s.joints[j].parent;
      found = true;
    }
    if (!found) throw TableError("body '" + body + "' is not connected to ground by joints");
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

// GSL natural cubic spline through (q, y) over a range (not periodic).
struct RangeSpline {
  std::unique_ptr<gsl_spline, decltype(&gsl_spline_free)> sp{nullptr, gsl_spline_free};
  double lo, hi;
  RangeSpline(const std::vector<double>& q, const std::vector<double>& v) : lo(q.front()), hi(q.back()) {
    sp.reset(gsl_spline_alloc(gsl_interp_cspline, q.size()));
    gsl_spline_init(sp.get(), q.data(), v.data(), q.size());
  }
  double eval(double q) const { return q < lo || q > hi ? NAN : gsl_spline_eval(sp.get(), q, nullptr); }
};

// ∫ from q[0] to q[i] of the range tables' not-a-knot cubic spline through (q, y) (uniform grid),
// for every grid point: the non-periodic integral of the integrated method, m1 from the range's
// minimum. Each interval's cubic a + b x + c x² + d x³ integrates to a h + b h²/2 + c h³/3 + d h⁴/4.
std::vector<double> range_integral(const std::vector<double>& q, const std::vector<double>& y) {
  Samples one;
  one.periodic = false;
  one.q0 = q.front();
  one.step = (q.back() - q.front()) / static_cast<double>(q.size() - 1);
  one.q = q;
  one.add("m2", y);
  const Table t = build_table(one, Interpolation::CubicSpline);
  const double h = t.step;
  std::vector<double> out(q.size(), 0.0);
  for (int iv = 0; iv < t.intervals; ++iv) {
    const double* c = &t.coef[static_cast<size_t>(iv) * 4];
    out[iv + 1] = out[iv] + h * (c[0] + h * (c[1] / 2 + h * (c[2] / 3 + h * c[3] / 4)));
  }
  return out;
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

long check_grid_step(double step_rad) {
  const double deg = step_rad * 180 / kPi;
  const auto range = fmt::format(
      "valid grid steps are {}° to {}° (at most {} and at least {} points a turn) and divide 360°", kMinGridDeg,
      kMaxGridDeg, std::lround(360 / kMinGridDeg), std::lround(360 / kMaxGridDeg));
  if (!std::isfinite(deg)) throw TableError(fmt::format("grid step {}° is not a finite number; {}", deg, range));
  // The bounds hold to rounding, so 360/36000 written in radians is still accepted.
  if (deg < kMinGridDeg * (1 - 1e-9) || deg > kMaxGridDeg * (1 + 1e-9))
    throw TableError(fmt::format("grid step {:.6g}° is out of range: {}", deg, range));
  const double n_real = 360.0 / deg;
  const long n = std::lround(n_real);
  if (std::abs(n_real - static_cast<double>(n)) > 1e-6)
    throw TableError(
        fmt::format("grid step {:.6g}° does not divide 360° ({:.6g} points a turn): {}", deg, n_real, range));
  return n;
}

long range_intervals(double span, double step_rad, bool revolute, bool ends_at_dead_point) {
  if (!(std::isfinite(span) && span > 0))
    throw TableError(fmt::format("the range of the independent coordinate must be finite and positive (got {:g})",
                                 span));
  // A range table never has fewer intervals than a full turn at the same grid (360/g): a rocker
  // swinging 48° at 10° would otherwise get 5 intervals, and its reduced speed missed the full
  // model's by 24 % (fourbar-rocker); a revolute range wider than that keeps intervals ≤ g.
  const double per_turn = std::round(2 * kPi / step_rad);
  const double n = revolute ? std::max(per_turn, std::ceil(span / step_rad - 1e-9)) : per_turn;
  if (!(n + 1 <= static_cast<double>(kMaxTableRows)))
    throw TableError(fmt::format("a range table of {:.6g} with a {:.6g}° grid would have {:.3g} points, more than {}",
                                 span, step_rad * 180 / kPi, n + 1, kMaxTableRows));
  const long base = std::max(4L, static_cast<long>(n));
  if (!ends_at_dead_point) return base;
  return std::min(base * kDeadPointRefinement, kMaxTableRows - 1);
}

namespace {

// The grid of a table and the sizes of its columns, fixed before any sampling.
struct GridPlan {
  long n = 0;            // grid points
  double h = 0.0;        // grid step [rad or m]
  bool periodic = true, revolute = true;
  int nk = 0, nj = 0;    // constraint forces, joints
  long npf = 0;          // point forces
};

// Checks the grid and the table's size against the reader's limits (samples.hpp) before any
// allocation, and fills the table's header and grid (s.q from the point nearest the initial q
// for a turn, from the range's minimum otherwise).
GridPlan plan_grid(KinetostaticSource& src, const models::Scene& scene, const ExtractOptions& opt, Samples& s) {
  const long per_turn = check_grid_step(opt.step_rad);  // before any allocation
  const auto* ind_joint = scene.find_joint(scene.independent);
  if (!ind_joint) throw TableError("the independent joint '" + scene.independent + "' does not exist");
  GridPlan g;
  g.revolute = ind_joint->type == models::JointType::Revolute;
  g.periodic = !opt.range;
  if (!g.revolute && g.periodic)
    throw TableError("a prismatic independent coordinate needs a range: a table over [q_min, q_max] "
                     "(independent_range, or the range rdyn finds from the dead points)");
  if (!std::isfinite(scene.initial.q)) throw TableError("the initial q is not finite");
  // A range found from the dead points is sampled finer (kDeadPointRefinement): m1 ∝ 1/distance there.
  const bool dead_edge = opt.range && (opt.range->min_edge == "dead point" || opt.range->max_edge == "dead point");
  g.n = g.periodic ? per_turn : range_intervals(opt.range->max - opt.range->min, opt.step_rad, g.revolute, dead_edge) + 1;
  g.h = g.periodic ? 2 * kPi / g.n : (opt.range->max - opt.range->min) / static_cast<double>(g.n - 1);
  g.nk = src.num_constraint_forces(), g.nj = src.num_joints();
  if (g.nk != static_cast<int>(scene.outputs.constraint_forces.size()) || g.nj != static_cast<int>(scene.joints.size()))
    throw TableError("the kinetostatic source does not match the scene (constraint forces or joints differ)");
  // The table must be one the reader accepts (samples.hpp limits): count its columns first
  // (m1, m2, Q_cons, V; me1, me2, Qx_cons per force; r per joint; rx per force and joint;
  // w and wx per resistance) and refuse before allocating.
  long profiled = 0;  // joint torques with a profile: one tau_<load> column each
  for (const auto& t : scene.joint_torques) profiled += t.profile ? 1 : 0;
  for (const auto& f : scene.point_forces) profiled += f.profile ? 1 : 0;
  g.npf = static_cast<long>(scene.point_forces.size());  // Qpf_ and Qxpf_ columns each
  const int nk = g.nk, nj = g.nj;
  const long cols = 4 + 3L * nk + nj + static_cast<long>(nk) * nj + static_cast<long>(scene.resistances.size()) * (1 + nk) +
                    profiled + g.npf * (1 + nk) + (wants_joint_outputs(scene) ? 2L * nj : 0L);  // p_, k_ (reduced/joint_outputs.hpp)
  if (cols + 1 > kMaxTableColumns || (cols + 1) * g.n > kMaxTableValues)
    throw TableError(fmt::format("a {:g}° table of this scene would have {} points × {} columns, more than the limits "
                                 "of {} columns and {} values: use a coarser grid or request fewer constraint forces",
                                 opt.step_rad * 180 / kPi, g.n, cols + 1, kMaxTableColumns, kMaxTableValues));
  s.scene = scene.name;
  s.scene_hash = models::scene_hash(scene);
  s.method = method_name(opt.method);
  s.periodic = g.periodic;
  s.revolute = g.revolute;
  s.step = g.h;
  if (g.periodic) {
    // Grid anchored at 0, visited from the point nearest the initial q.
    const long first = std::lround(scene.initial.q / g.h);
    for (long i = 0; i < g.n; ++i) s.q.push_back((first + i) * g.h);
  } else {
    // From the range's minimum upward; the last point is the maximum itself.
    for (long i = 0; i < g.n; ++i) s.q.push_back(i + 1 == g.n ? opt.range->max : opt.range->min + i * g.h);
    s.min_edge = opt.range->min_edge;
    s.max_edge = opt.range->max_edge;
  }
  s.q0 = s.q[0];
  return g;
}

// The columns of the sweep, indexed [point], [force][point], [joint][point] and so on.
struct SweepColumns {
  std::vector<double> m1, m2, Q, V;
  std::vector<std::vector<double>> me1, me2, Qx, r, slope, p, theta, Lq;
  std::vector<std::vector<std::vector<double>>> rx, Lx;  // [force][joint or point force][point]
  bool slopes = true;                                     // d r_j/dq, when every sample gives it
  std::vector<char> singular, limited;  // limited: a singular point given its exact limit
  std::vector<std::vector<double>> poles;  // [force]: singular points where its columns have a pole
  // Singular grid points given their limit, with the pole residues their side samples show.
  std::vector<std::pair<long, std::vector<std::array<double, 3>>>> pole_residues;
  double min_conditioning = 1.0;  // over the grid samples
  // Joints gating loads (their ratio's zeros are the switch angles, refined during the sweep)
  // and the zeros found; joints whose angle a profiled load reads.
  std::vector<int> gate_joints, profile_joints;
  std::vector<std::vector<double>> gate_roots;

  SweepColumns(const GridPlan& g, const models::Scene& scene) {
    const long n = g.n;
    m1.assign(n, 0.0), m2 = Q = V = m1;
    me1.assign(g.nk, std::vector<double>(n)), me2 = Qx = me1;
    r.assign(g.nj, std::vector<double>(n)), slope = r;
    rx.assign(g.nk, r);
    Lq.assign(g.npf, std::vector<double>(n));  // dL/dq of each point force's line
    Lx.assign(g.nk, Lq);                       // dL/dx_k
    singular.assign(n, 0), limited = singular;
    poles.resize(g.nk);
    p.assign(wants_joint_outputs(scene) ? g.nj : 0, std::vector<double>(n));
    auto add_gate_joint = [&](const std::optional<models::RateGate>& gate) {
      if (!gate) return;
      const int j = scene.joint_index(gate->joint);
      if (std::find(gate_joints.begin(), gate_joints.end(), j) == gate_joints.end()) gate_joints.push_back(j);
    };
    for (const auto& t : scene.joint_torques) add_gate_joint(t.active_when);
    for (const auto& f : scene.point_forces) add_gate_joint(f.active_when);
    gate_roots.resize(gate_joints.size());
    auto add_profile_joint = [&](const std::string& load, const std::optional<models::LoadProfile>& pr) {
      if (!pr) return;
      const int j = scene.joint_index(pr->of);
      if (j < 0) throw TableError("profile of load '" + load + "' reads unknown joint '" + pr->of + "'");
      if (std::find(profile_joints.begin(), profile_joints.end(), j) == profile_joints.end()) profile_joints.push_back(j);
    };
    for (const auto& t : scene.joint_torques) add_profile_joint(t.name, t.profile);
    for (const auto& f : scene.point_forces) add_profile_joint(f.name, f.profile);
    theta.assign(profile_joints.size(), std::vector<double>(n));
  }
  long profile_index(int joint) const {
    return std::find(profile_joints.begin(), profile_joints.end(), joint) - profile_joints.begin();
  }
};

// The inertial parameters of the routes that do not take them from the grid visit: the paper's
// two prescribed-motion sweeps, or the mass matrix directly.
void sweep_inertial(KinetostaticSource& src, const ExtractOptions& opt, const GridPlan& g, const Samples& s,
                    SweepColumns& c) {
  const long n = g.n;
  const int nk = g.nk;
  if (opt.method == Method::PaperSweep) {
    // (i) constant speed: q(t) = q_first + ω t sampled at t_i = i h/ω (q̈ = 0).
    const double w = 1.0;
    const double lin[5] = {s.q0, w, 0.0, 0.0, 0.0};
    for (long i = 0; i < n; ++i) {
      const auto p = src.harmonic_sweep(lin, i * g.h / w);
      if (!p) throw TableError("this source cannot run prescribed-motion sweeps");
      c.m2[i] = p->driving_force / (w * w);
      for (int k = 0; k < nk; ++k) c.me2[k][i] = p->constraint_forces[k] / (w * w);
    }
    // (ii) the paper's law q(t) = c1 + c2 t + c3 cos(c4 t + c5), one oscillation per grid
    // interval (c4 = 2π/τ, τ = 1 s, c2 = h/τ) with c5 = π/4 and c3 = c2/(c4 sin c5), so that at
    // t_i = iτ: q = q_i, q̇ = c2 − c3 c4 sin c5 = 0 and q̈ = −c3 c4² cos c5 = −c2 c4 ≠ 0.
    const double tau = 1.0, c2 = g.h / tau, c4 = 2 * kPi / tau, c5 = kPi / 4, c3 = c2 / (c4 * std::sin(c5));
    const double c1 = s.q0 - c3 * std::cos(c5);
    const double law[5] = {c1, c2, c3, c4, c5};
    const double qdd = -c3 * c4 * c4 * std::cos(c5);
    for (long i = 0; i < n; ++i) {
      const auto p = src.harmonic_sweep(law, i * tau);
      if (!p) throw TableError("this source cannot run prescribed-motion sweeps");
      c.m1[i] = p->driving_force / qdd;
      for (int k = 0; k < nk; ++k) c.me1[k][i] = p->constraint_forces[k] / qdd;
    }
  } else if (opt.method == Method::Direct) {
    for (long i = 0; i < n; ++i) {
      const auto d = src.direct(s.q[i]);
      if (!d) throw TableError("this source cannot compute the direct (mass-matrix) route");
      c.m1[i] = d->m1;
      c.m2[i] = d->m2;
      for (int k = 0; k < nk; ++k) c.me1[k][i] = d->me1[k], c.me2[k][i] = d->me2[k];
    }
  }
}

// Sign change of gate joint gj's ratio between samples i0 and i1 (i1 may wrap to 0 + 2π): the
// switch angle, by Newton on the slopes when every sample gave them, else by root finding.
void bracket_gate(KinetostaticSource& src, const GridPlan& g, const Samples& s, SweepColumns& c, size_t gj, long i0,
                  long i1, double x1_offset) {
  const long n = g.n;
  const int j = c.gate_joints[gj];
  const double a = s.q[i0], b = s.q[i1] + x1_offset, ra = c.r[j][i0], rb = c.r[j][i1];
  if (!(ra == 0.0 || ((ra > 0) != (rb > 0) && rb != 0.0))) return;
  const long im = (i0 + n - 1) % n;
  const double xm = s.q[im] - (im > i0 ? 2 * kPi : 0.0);
  // A range table has no sample before its first point: the chord there.
  const double est = !g.periodic && i0 == 0 ? a - ra * (b - a) / (rb - ra) : quadratic_zero(xm, c.r[j][im], a, ra, b, rb);
  std::optional<double> root;
  if (c.slopes) root = newton_root(src, j, a, ra, c.slope[j][i0], b, rb, c.slope[j][i1]);
  c.gate_roots[gj].push_back(root ? *root : refine_root(src, j, a, ra, b, rb, est));
}

// A point force's line shortening then lengthening between samples i0 and i1: its points may meet in
// between (the full model stops there; so does the extraction, PointForceMeeting naming the load).
void check_point_force_meeting(KinetostaticSource& src, const models::Scene& scene, const Samples& s,
                               const SweepColumns& c, long i0, long i1, double offset) {
  for (size_t f = 0; f < c.Lq.size(); ++f)
    if (c.Lq[f][i0] < 0 && c.Lq[f][i1] > 0)
      if (const auto qm = find_point_force_meeting(src, static_cast<long>(f), s.q[i0], c.Lq[f][i0], s.q[i1] + offset,
                                                   c.Lq[f][i1]))
        throw PointForceMeeting(
            fmt::format("point force '{}': its points meet near q = {:.6g} between grid points (the line's length "
                        "reaches zero and its direction reverses), where the line of action has no direction; the "
                        "full model stops there too; move the attachment points apart",
                        scene.point_forces[f].name, *qm >= s.q[0] + 2 * kPi ? *qm - 2 * kPi : *qm),
            *qm >= s.q[0] + 2 * kPi ? *qm - 2 * kPi : *qm, scene.point_forces[f].name);
}

// Stores one grid sample's values in the columns.
void store_sample(const GridSample& gs, long i, const GridPlan& g, SweepColumns& c) {
  const int nk = g.nk, nj = g.nj;
  // At rest: T_act + Q = 0 and F_E + Qx = 0.
  c.Q[i] = -gs.conservative.forces.driving_force;
  c.V[i] = gs.conservative.potential_energy;
  for (int k = 0; k < nk; ++k) c.Qx[k][i] = -gs.conservative.forces.constraint_forces[k];
  if (!c.p.empty()) {  // joint positions for the joint-output columns (reduced/joint_outputs.hpp)
    if (static_cast<int>(gs.ratios.joint_q.size()) != nj)
      throw TableError("this kinetostatic source does not give joint positions, which outputs.joints, "
                       "outputs.reactions and outputs.shaking need");
    for (int j = 0; j < nj; ++j) c.p[j][i] = gs.ratios.joint_q[j];
  }
  c.slopes &= static_cast<int>(gs.ratios.wrt_q_slope.size()) == nj;
  for (int j = 0; j < nj; ++j) {
    c.r[j][i] = gs.ratios.wrt_q[j];
    if (c.slopes) c.slope[j][i] = gs.ratios.wrt_q_slope[j];
    for (int k = 0; k < nk; ++k) c.rx[k][j][i] = gs.ratios.wrt_x[k][j];
  }
  if (g.npf > 0) {
    if (static_cast<long>(gs.ratios.length_wrt_q.size()) != g.npf ||
        static_cast<int>(gs.ratios.length_wrt_x.size()) != nk)
      throw TableError("this kinetostatic source does not give the length rates of point forces, which the "
                       "reduced model needs for them");
    for (long f = 0; f < g.npf; ++f) {
      c.Lq[f][i] = gs.ratios.length_wrt_q[f];
      for (int k = 0; k < nk; ++k) c.Lx[k][f][i] = gs.ratios.length_wrt_x[k].at(f);
    }
  }
  c.singular[i] = gs.singular;
}

// One visit per grid point: (i) and (ii) when the method needs them, the static call for
// position-only loads (only when the scene has some), and the velocity ratios; the gates'
// switch angles and the point forces' meetings between consecutive points.
// A configuration of rank loss between grid points (ExtractOptions::singular_hints): the pole
// test of a singular grid point (sweep_refine.hpp) at q_s, its residue confirmed at q_s ± 4δ
// (4δ ≤ the grid step) as find_force_poles confirms it at the grid neighbours; a pole is listed
// like a grid point's. The samples run forward, q_s − 4δ to q_s + 4δ, crossing q_s once as the
// sweep does. Returns nothing; the sweep goes on to the next grid point.
void check_pole_between(KinetostaticSource& src, double q_s, const GridPlan& g, bool conservative_loads,
                        SweepColumns& c) {
  const double d = std::min(kSingularLimitStep_rad, g.h / 4);
  const GridSample lo = src.sample(q_s - 4 * d, conservative_loads);
  GridSample at;  // the limit's own values are not kept: only the residues
  std::vector<std::array<double, 3>> res;
  if (!calc_singular_limit(src, q_s, g.h, conservative_loads, at, &res)) return;
  const GridSample hi = src.sample(q_s + 4 * d, conservative_loads);
  for (int k = 0; k < g.nk && k < static_cast<int>(res.size()); ++k) {
    const double far[3] = {
        hi.acceleration.constraint_forces.at(k) - lo.acceleration.constraint_forces.at(k),
        hi.velocity.constraint_forces.at(k) - lo.velocity.constraint_forces.at(k),
        hi.conservative.forces.constraint_forces.size() > static_cast<size_t>(k) &&
                lo.conservative.forces.constraint_forces.size() > static_cast<size_t>(k)
            ? hi.conservative.forces.constraint_forces[k] - lo.conservative.forces.constraint_forces[k]
            : 0.0};
    bool pole = false;
    for (int j = 0; j < 3; ++j) {
      const double a = res[k][j];
      if (a != 0.0) pole = pole || std::abs(0.5 * far[j] * 4 * d - a) < 0.3 * std::abs(a);
    }
    if (pole) c.poles[k].push_back(q_s);
  }
}

// The hints inside (a, b), a turn's hints mapped into [q_first, q_first + 2π) when periodic.
std::vector<double> hints_between(const ExtractOptions& opt, const GridPlan& g, double q_first, double a, double b) {
  std::vector<double> out;
  for (double q : opt.singular_hints) {
    if (!std::isfinite(q)) continue;
    if (g.periodic) q = q_first + std::fmod(std::fmod(q - q_first, 2 * kPi) + 2 * kPi, 2 * kPi);
    const double eps = 1e-9 * std::max(1.0, std::abs(q));
    if (q > a + eps && q < b - eps) out.push_back(q);
  }
  std::sort(out.begin(), out.end());
  return out;
}

void sweep_grid(KinetostaticSource& src, const models::Scene& scene, const ExtractOptions& opt, const GridPlan& g,
                const Samples& s, SweepColumns& c) {
  const long n = g.n;
  const int nk = g.nk;
  const bool conservative_loads = scene.gravity.enabled || !scene.springs.empty();
  const bool inertial_here = opt.method == Method::Kinetostatic || opt.method == Method::Integrated;
  for (long i = 0; i < n; ++i) {
    GridSample gs;
    if (inertial_here) {
      if (i >= 1)
        for (double q_s : hints_between(opt, g, s.q[0], s.q[i - 1], s.q[i]))
          check_pole_between(src, q_s, g, conservative_loads, c);
      gs = src.sample(s.q[i], conservative_loads);
      c.min_conditioning = std::min(c.min_conditioning, gs.conditioning);
      // A singular grid point gets the limit along the branch from both sides (a range's end
      // points have one side only: they keep the repair below, which refuses them).
      if (gs.singular && (g.periodic || (i > 0 && i < n - 1))) {
        std::vector<std::array<double, 3>> residues;
        c.limited[i] = calc_singular_limit(src, s.q[i], g.h, conservative_loads, gs, &residues);
        if (c.limited[i]) c.pole_residues.emplace_back(i, std::move(residues));
      }
      c.m2[i] = gs.velocity.driving_force;      // (i) q̇ = 1, q̈ = 0
      c.m1[i] = gs.acceleration.driving_force;  // (ii) q̇ = 0, q̈ = 1
      for (int k = 0; k < nk; ++k)
        c.me2[k][i] = gs.velocity.constraint_forces[k], c.me1[k][i] = gs.acceleration.constraint_forces[k];
    } else {
      if (conservative_loads) gs.conservative = src.conservative(s.q[i]);
      else gs.conservative.forces.constraint_forces.assign(nk, 0.0);
      gs.ratios = src.ratios(s.q[i]);
    }
    store_sample(gs, i, g, c);
    if (g.npf > 0) {
      if (i >= 1) check_point_force_meeting(src, scene, s, c, i - 1, i, 0.0);
      if (g.periodic && i == n - 1) check_point_force_meeting(src, scene, s, c, n - 1, 0, 2 * kPi);
    }
    for (size_t pj = 0; pj < c.profile_joints.size(); ++pj) {
      const auto th = src.joint_coordinate(s.q[i], c.profile_joints[pj]);
      if (!th) throw TableError("this kinetostatic source cannot give joint angles, which profiled loads need");
      c.theta[pj][i] = *th;
    }
    if (i >= 1)
      for (size_t gj = 0; gj < c.gate_joints.size(); ++gj) bracket_gate(src, g, s, c, gj, i - 1, i, 0.0);
  }
  if (g.periodic)  // the wrap-around interval
    for (size_t gj = 0; gj < c.gate_joints.size(); ++gj) bracket_gate(src, g, s, c, gj, n - 1, 0, 2 * kPi);
}

// The turn must close: the first regular grid point again, a turn later, on the same branch. A
// sweep that stepped over a blocked range narrower than a grid step (a non-Grashof four-bar
// blocked over 2°) lands on the other assembly and stays there: m1 and the velocity ratios differ
// at O(1) where on one branch they agree to the projection's 1e-12.
void check_turn_closes(KinetostaticSource& src, const models::Scene& scene, const GridPlan& g, const Samples& s,
                       const SweepColumns& c) {
  // The first regular grid point (a singular one's values are least-squares, repaired below).
  long i0 = 0;
  while (i0 < g.n && c.singular[i0]) ++i0;
  if (i0 >= g.n) return;
  const GridSample gs = src.sample(s.q[i0] + 2 * kPi, false);
  auto scale = [&](const std::vector<double>& col) {
    double v = 1e-300;
    for (double x : col) v = std::max(v, std::abs(x));
    return v;
  };
  std::string off;
  if (!gs.singular) {
    if (!(std::abs(gs.acceleration.driving_force - c.m1[i0]) <= 1e-7 * scale(c.m1)))
      off = fmt::format("m1 {:.6g} against {:.6g}", gs.acceleration.driving_force, c.m1[i0]);
    for (int j = 0; j < g.nj && off.empty() && static_cast<int>(gs.ratios.wrt_q.size()) == g.nj; ++j)
      if (!(std::abs(gs.ratios.wrt_q[j] - c.r[j][i0]) <= 1e-7 * std::max(1.0, scale(c.r[j]))))
        off = fmt::format("the velocity ratio of joint '{}' {:.6g} against {:.6g}", scene.joints[j].name,
                          gs.ratios.wrt_q[j], c.r[j][i0]);
  }
  if (off.empty()) return;
  // Through a configuration of rank loss the branch followed may come back only after two
  // turns (a four-bar at its Grashof change point: crank 1, coupler 2, rocker 2, ground 1): no
  // grid closes one turn then, so finer grids are no advice.
  std::string singular;
  for (long i = 0; i < g.n; ++i)
    if (c.singular[i]) singular += fmt::format("{}{:.6g}°", singular.empty() ? "" : ", ", s.q[i] * 180 / kPi);
  // Geared so that one turn does not bring every joint back (a five-bar driven from the fast crank of
  // a 2:1 pair): no grid closes one turn; the slow joint repeats each turn (was "a finer grid").
  std::string gears_why;
  if (const int turns = models::calc_turns_to_repeat(scene, gears_why); turns != 1)
    throw SweepNotClosed(fmt::format(
        "{}: the sweep of '{}' over a full turn does not return to its start (a turn later at {:.6g}° it finds {}): "
        "{}, so the mechanism {}; a table over one turn cannot describe it. Make the joint that turns the fewest "
        "times the independent coordinate (every joint then repeats each turn of it), or use the full model",
        scene.source_file, scene.independent, s.q[i0] * 180 / kPi, off, gears_why,
        turns > 1 ? fmt::format("repeats only every {} turns of '{}'", turns, scene.independent) : "never repeats"));
  const std::string advice =
      singular.empty()
          ? "extract on a finer grid (--grid-deg)"
          : "the sweep passed configurations of rank loss at " + singular +
                ", where branches cross: if the branch through them repeats only every two turns (a linkage at its "
                "change point), no grid closes one turn and a table of this mechanism needs a declared "
                "independent_range inside one turn; otherwise extract on a finer grid (--grid-deg)";
  throw SweepNotClosed(fmt::format(
      "{}: the sweep of '{}' over a full turn does not return to its start: a turn later at {:.6g}° it finds {} "
      "— it changed assembly between two grid points of {:g}°, where the predictor from the last grid point "
      "reached the other branch (a nearly singular stretch, a crossing of branches, or a dead point with a "
      "blocked range narrower than the step); {}",
      scene.source_file, scene.independent, s.q[i0] * 180 / kPi, off, g.h * 180 / kPi, advice));
}

// A pole shape at a singular grid point (sweep_refine.hpp, is_simple_pole) is a pole of the
// branch when the grid neighbours show the same residue: ½[f(q_s + h) − f(q_s − h)]·h = a + O(h²)
// within 30 %. Rounding noise that took the shape at the side samples shows a residue ~1e-16
// there, not the neighbours' h²·f'.
void find_force_poles(const GridPlan& g, const Samples& s, SweepColumns& c) {
  for (const auto& [i, res] : c.pole_residues) {
    if (!g.periodic && (i == 0 || i + 1 >= g.n)) continue;
    const long lo = (i - 1 + g.n) % g.n, hi = (i + 1) % g.n;
    for (int k = 0; k < g.nk; ++k) {
      const std::vector<double>* cols[3] = {&c.me1[k], &c.me2[k], &c.Qx[k]};
      bool pole = false;
      for (int j = 0; j < 3; ++j) {
        const double a = res.at(k)[j];
        if (a == 0.0) continue;
        const double a_grid = 0.5 * ((*cols[j])[hi] - (*cols[j])[lo]) * g.h;
        pole = pole || std::abs(a_grid - a) < 0.3 * std::abs(a);
      }
      if (pole) c.poles[k].push_back(s.q[i]);
    }
  }
}

// Samples at singular configurations (loop Jacobian lost rank) that could not take their limit
// carry velocities the constraints do not determine: every column there is replaced by a
// periodic cubic spline through the regular samples, i.e. the limit along the branch the sweep
// follows (inside a range the natural spline; a singular end point stays NaN and fails the
// finite check: a range must stop short of singularities).
void repair_singular_samples(const GridPlan& g, Samples& s, SweepColumns& c) {
  const long n = g.n;
  if (std::count(c.singular.begin(), c.singular.end(), 1) == 0) return;
  for (long i = 0; i < n; ++i)
    if (c.singular[i]) s.singular_q.push_back(s.q[i]);
  auto repair = [&](std::vector<double>& col) {
    std::vector<double> x, y;
    for (long i = 0; i < n; ++i)
      if (!c.singular[i] || c.limited[i]) x.push_back(s.q[i]), y.push_back(col[i]);
    if (x.size() < 4 || x.size() == static_cast<size_t>(n)) return;
    if (!g.periodic) {
      const RangeSpline sp(x, y);
      for (long i = 0; i < n; ++i)
        if (c.singular[i] && !c.limited[i]) col[i] = sp.eval(s.q[i]);
      return;
    }
    const PeriodicSpline sp(x, y, 2 * kPi);
    for (long i = 0; i < n; ++i)
      if (c.singular[i] && !c.limited[i]) col[i] = sp.eval(s.q[i]);
  };
  for (auto* col : {&c.m1, &c.m2, &c.Q, &c.V}) repair(*col);
  for (int k = 0; k < g.nk; ++k) repair(c.me1[k]), repair(c.me2[k]), repair(c.Qx[k]);
  for (int j = 0; j < g.nj; ++j) {
    repair(c.r[j]);
    for (int k = 0; k < g.nk; ++k) repair(c.rx[k][j]);
  }
  for (long f = 0; f < g.npf; ++f) {
    repair(c.Lq[f]);
    for (int k = 0; k < g.nk; ++k) repair(c.Lx[k][f]);
  }
}

// The load columns after the inertial ones: profiles per unit amplitude, point forces'
// generalized forces per unit tension, the gates' switch angles, the resisted bodies' rates.
void add_load_columns(const models::Scene& scene, const GridPlan& g, const SweepColumns& c, Samples& s) {
  const long n = g.n;
  const auto& forces = scene.outputs.constraint_forces;
  auto tau_of = [&](const models::LoadProfile& pr) {
    const long pj = c.profile_index(scene.joint_index(pr.of));
    std::vector<double> tau(n);
    for (long i = 0; i < n; ++i) tau[i] = models::calc_profile(pr, c.theta[pj][i]);
    return tau;
  };
  // Profiled drive loads are position-only (apart from their gate): tabulate each profile per
  // unit amplitude along the grid, τ(θ_of(q)); the model applies value·τ·r_j (virtual power).
  for (const auto& t : scene.joint_torques)
    if (t.profile) s.add("tau_" + t.name, tau_of(*t.profile));
  // Point forces: generalized force per unit tension by virtual power. A tension T pulling the
  // points together does power −T·L̇ = −T·(dL/dq)·q̇, so Q = −T·dL/dq on q and −T·dL/dx_k along
  // x_k (docs/theory.md §3); with a profile, T = value·τ(θ_of(q)) (tau_<load> as for torques).
  for (long f = 0; f < g.npf; ++f) {
    const auto& pf = scene.point_forces[f];
    std::vector<double> Q1(n);
    for (long i = 0; i < n; ++i) Q1[i] = -c.Lq[f][i];
    s.add("Qpf_" + pf.name, Q1);
    for (int k = 0; k < g.nk; ++k) {
      std::vector<double> Qk(n);
      for (long i = 0; i < n; ++i) Qk[i] = -c.Lx[k][f][i];
      s.add("Qxpf_" + forces[k].name + "_" + pf.name, Qk);
    }
    if (pf.profile) s.add("tau_" + pf.name, tau_of(*pf.profile));
  }
  // Switch angles of rate-gated loads: the zeros located during the sweep.
  for (size_t gj = 0; gj < c.gate_joints.size(); ++gj) {
    auto roots = c.gate_roots[gj];
    std::sort(roots.begin(), roots.end());
    s.roots.emplace_back("r_" + scene.joints[c.gate_joints[gj]].name, roots);
  }
  // Body angular rates for the bodies that carry a resistance.
  for (const auto& res : scene.resistances) {
    if (s.column("w_" + res.body) >= 0) continue;
    const auto path = revolute_path(scene, res.body);
    std::vector<double> w(n, 0.0);
    std::vector<std::vector<double>> wx(g.nk, std::vector<double>(n, 0.0));
    for (int j : path)
      for (long i = 0; i < n; ++i) {
        w[i] += c.r[j][i];
        for (int k = 0; k < g.nk; ++k) wx[k][i] += c.rx[k][j][i];
      }
    s.add("w_" + res.body, w);
    for (int k = 0; k < g.nk; ++k) s.add("wx_" + forces[k].name + "_" + res.body, wx[k]);
  }
}

// Nothing non-finite leaves extraction: a sample the full model could not compute (a singular
// configuration the repair could not bridge, a redundant loop) fails the run.
void check_finite_table(const models::Scene& scene, const Samples& s) {
  for (size_t c = 0; c < s.columns.size(); ++c)
    for (size_t i = 0; i < s.q.size(); ++i)
      if (!std::isfinite(s.columns[c][i]))
        throw models::NumericalError(fmt::format(
            "extraction produced a non-finite value ({}) in column '{}' at q = {:.6g}° of scene '{}'; the full model "
            "cannot be sampled there (a singular or redundant configuration)",
            s.columns[c][i], s.names[c], s.revolute ? s.q[i] * 180 / kPi : s.q[i], scene.name));
  for (const auto& [col, rs] : s.roots)
    for (double r : rs)
      if (!std::isfinite(r))
        throw models::NumericalError(
            fmt::format("extraction located a non-finite switch angle of column '{}' in scene '{}'", col, scene.name));
}

}  // namespace

Samples extract_samples(KinetostaticSource& src, const models::Scene& scene, const ExtractOptions& opt) {
  gsl_set_error_handler_off();  // GSL reports through return codes, never abort()
  Samples s;
  const GridPlan g = plan_grid(src, scene, opt, s);
  SweepColumns c(g, scene);
  sweep_inertial(src, opt, g, s, c);
  sweep_grid(src, scene, opt, g, s, c);
  const bool inertial_here = opt.method == Method::Kinetostatic || opt.method == Method::Integrated;
  if (g.periodic && inertial_here && opt.require_closed_turn) check_turn_closes(src, scene, g, s, c);
  if (opt.method == Method::Integrated) {
    // m1(q) = m1(q_first) + ∫ dm1/dq dq with dm1/dq = 2 m2 (Eksergian: m2 = ½ dm1/dq).
    std::vector<double> two_m2(g.n);
    for (long i = 0; i < g.n; ++i) two_m2[i] = 2 * c.m2[i];
    const auto integral = g.periodic ? periodic_integral(s.q, two_m2, 2 * kPi) : range_integral(s.q, two_m2);
    for (long i = 1; i < g.n; ++i) c.m1[i] = c.m1[0] + integral[i];
  }
  find_force_poles(g, s, c);
  for (auto& p : c.poles) std::sort(p.begin(), p.end());  // grid points' and between them
  s.min_conditioning = c.min_conditioning;
  repair_singular_samples(g, s, c);
  const auto& forces = scene.outputs.constraint_forces;
  s.add("m1", c.m1);
  s.add("m2", c.m2);
  for (int k = 0; k < g.nk; ++k) {
    s.add("me1_" + forces[k].name, c.me1[k]);
    s.add("me2_" + forces[k].name, c.me2[k]);
  }
  for (int k = 0; k < g.nk; ++k)
    if (!c.poles[k].empty()) s.poles.emplace_back(forces[k].name, c.poles[k]);
  s.add("Q_cons", c.Q);
  s.add("V", c.V);
  for (int k = 0; k < g.nk; ++k) s.add("Qx_cons_" + forces[k].name, c.Qx[k]);
  for (int j = 0; j < g.nj; ++j) s.add("r_" + scene.joints[j].name, c.r[j]);
  for (int k = 0; k < g.nk; ++k)
    for (int j = 0; j < g.nj; ++j) s.add("rx_" + forces[k].name + "_" + scene.joints[j].name, c.rx[k][j]);
  if (!c.p.empty()) add_joint_position_columns(scene, s.q, g.h, c.r, c.p, s);
  add_load_columns(scene, g, c, s);
  if (!c.p.empty()) turn_reaction_lines_to_ground(scene, s);  // joint_outputs.hpp: ground-frame lines
  check_finite_table(scene, s);
  return s;
}

}  // namespace rdyn::reduced
