// Rates along the assembly branch and the projections they need (engine/branch_rates.hpp).
#include "engine/branch_rates.hpp"

#include <algorithm>
#include <cmath>

#include "engine/kinetostatic.hpp"

namespace rdyn::engine {

using namespace SimTK;


namespace {

// J.G's columns split into the free mobilities' (all but the independent coordinate and the
// constraint actuators): J.free_cols and J.G_free.
void split_jacobian(const FullModel::Impl& m, const State& s, SplitJacobian& J) {
  std::vector<bool> keep(s.getNU(), true);
  keep[m.joint_mobod[m.independent].getFirstUIndex(s)] = false;
  for (const auto& sl : m.actuator_slider) keep[sl.getFirstUIndex(s)] = false;
  J.free_cols.clear();
  for (int c = 0; c < s.getNU(); ++c)
    if (keep[c]) J.free_cols.push_back(c);
  J.G_free.resize(J.G.nrow(), static_cast<int>(J.free_cols.size()));
  for (int r = 0; r < J.G.nrow(); ++r)
    for (size_t c = 0; c < J.free_cols.size(); ++c) J.G_free(r, static_cast<int>(c)) = J.G(r, J.free_cols[c]);
}

}  // namespace

SplitJacobian calc_split_jacobian(const FullModel::Impl& m, const State& s) {
  SplitJacobian J;
  calc_constraint_jacobian(m, s, J.G);
  split_jacobian(m, s, J);
  return J;
}

// A scene joint's component of a mobility-space vector (folded joints through their gear).
double joint_part(const FullModel::Impl& m, const State& s, const Vector& u, int j) {
  if (const auto& f = m.joint_fold[j]) return f->ratio * joint_part(m, s, u, f->driver_joint);
  return u[m.joint_mobod[j].getFirstUIndex(s)];
}

// Position projection of the loop and gear closures by Newton's method with one Jacobian, that of
// the predicted configuration (a chord method): the prescribed coordinates (the independent one,
// the constraint actuators) stay as prescribeQ set them, the free ones move by the least-squares
// solution of G_free Δq = −perr (N = I for the pins and sliders rdyn builds, so dperr/dq = G).
// From the second-order predictor (perr ~1e-3 m at 10° steps) it contracts by about the
// predictor's error per iteration and reaches 1e-13 m in 3–4 iterations, where Simbody's
// projectQ rebuilt its own weighted constraint Jacobian on every iteration (issue #11 item 3:
// 44 % of the extraction). Returns false — the caller then runs projectQ as before — when the
// state is not of that kind (nq ≠ nu), the errors stop contracting by half per iteration (a
// singular configuration, a start too far from the branch) or 8 iterations do not suffice.
bool newton_project(const FullModel::Impl& m, State& s) {
  constexpr double kTolerance = 1e-13;  // [m, rad]: tighter than projectQ's 1e-12 (RMS)
  constexpr int kMaxIterations = 8;
  auto largest = [](const Vector& v) {
    double w = 0.0;
    for (int i = 0; i < v.size(); ++i) w = std::max(w, std::abs(v[i]));
    return w;  // NaN compares false below: not contracting
  };
  // Where the plan describes the state's rows, the errors and the chord's Jacobian come from the
  // coordinates alone (calc_constraint_errors_and_jacobian), and Simbody realizes only the
  // configuration the plan's errors accept: one Position realization a projection instead of
  // 2 (4–5 before the plan). A configuration is accepted on Simbody's own errors only, so a plan
  // that disagreed would cost iterations, never accuracy.
  const ConstraintJacobianPlan* plan = s.getNQ() == s.getNU() ? usable_plan(m, s) : nullptr;
  Vector e;
  SplitJacobian J;
  if (plan) {
    calc_constraint_errors_and_jacobian(*plan, s.getQ(), e, J.G);
  } else {
    m.system.realize(s, Stage::Position);
    e = s.getQErr();
  }
  double err = largest(e);
  if (err <= kTolerance) {
    if (!plan) return true;
    m.system.realize(s, Stage::Position);
    e = s.getQErr();
    if ((err = largest(e)) <= kTolerance) return true;
    plan = nullptr;  // closed by the plan's errors, not by Simbody's: Simbody's from here on
  }
  if (s.getNQ() != s.getNU()) return false;
  if (J.G.nrow() == 0) calc_constraint_jacobian(m, s, J.G);  // realized above
  split_jacobian(m, s, J);
  if (J.G.nrow() != s.getNQErr() || J.G_free.ncol() == 0) return false;
  // The q index of each free mobility (each mobilizer's q's and u's pair up one to one).
  std::vector<int> q_of(J.free_cols.size(), -1);
  if (const auto* p = m.jacobian_plan ? &*m.jacobian_plan : nullptr; p && p->nu == s.getNU()) {
    std::vector<int> q_of_u(s.getNU(), -1);
    for (const auto& mob : p->mobilities) q_of_u[mob.u] = mob.q;
    for (size_t c = 0; c < J.free_cols.size(); ++c) q_of[c] = q_of_u[J.free_cols[c]];
  } else {
    std::vector<int> q_of_u(s.getNU(), -1);
    for (int b = 0; b < m.matter.getNumBodies(); ++b) {
      const MobilizedBody& mb = m.matter.getMobilizedBody(MobilizedBodyIndex(b));
      if (mb.getNumQ(s) != mb.getNumU(s)) return false;
      for (int k = 0; k < mb.getNumU(s); ++k) q_of_u[mb.getFirstUIndex(s) + k] = mb.getFirstQIndex(s) + k;
    }
    for (size_t c = 0; c < J.free_cols.size(); ++c) q_of[c] = q_of_u[J.free_cols[c]];
  }
  for (int q : q_of)
    if (q < 0) return false;
  LeastSquares chord(J.G_free);  // one decomposition for every iteration
  Vector dx, rhs = e;
  for (int it = 0; it < kMaxIterations; ++it) {
    rhs *= -1.0;
    chord.solve(rhs, dx);
    Vector& q = s.updQ();
    for (size_t c = 0; c < q_of.size(); ++c) q[q_of[c]] += dx[static_cast<int>(c)];
    if (plan) calc_constraint_errors(*plan, s.getQ(), e);
    double next = plan ? largest(e) : NAN;
    if (!plan || next <= kTolerance) {
      m.system.realize(s, Stage::Position);
      next = largest(s.getQErr());
      if (next <= kTolerance) return true;
      plan = nullptr;  // closed by the plan's errors, not by Simbody's: Simbody's from here on
      e = s.getQErr();
    }
    if (!(next < 0.5 * err)) return false;
    err = next;
    rhs = e;
  }
  return false;
}

// Position projection with the independent coordinate prescribed: the chord Newton iteration,
// else Simbody's projectQ at 1e-12, else at 1e-9 (a singular configuration, counted). Throws
// what projectQ throws when none succeeds (the callers name the coordinate).
void project_prescribed(FullWorkspace::Impl& w) {
  const auto& m = w.model;
  State& s = w.state;
  m.system.realize(s, Stage::Time);
  m.system.prescribeQ(s);
  if (newton_project(m, s)) return;
  try {
    m.system.projectQ(s, 1e-12);
  } catch (const std::exception&) {
    m.system.projectQ(s, 1e-9);  // singular configuration: as project()
    ++w.near_singular_projections;
  }
}

// Near a singular configuration the rates carry the loop residual magnified by the
// conditioning κ: positions by 1/κ, velocity ratios by 1/κ², m2 (second-order terms) by 1/κ³;
// a residual of 1e-13 put m2 off by 1e-6 at 4e-3 rad from a parallelogram chain's flat
// configuration. Where κ < kPolishConditioning (regular mechanisms stay above: the bicycle
// 0.06, the hard high-saddle 0.0075; a chain's samples 4e-3 rad from flat 5e-4…2e-3), full Newton steps (a fresh Jacobian each) drive
// the residual down to rounding: at most 4, kept only while the residual falls.
void polish_projection(const FullModel::Impl& m, State& s) {
  auto worst = [&] {
    const Vector& e = s.getQErr();
    double w = 0.0;
    for (int i = 0; i < e.size(); ++i) w = std::max(w, std::abs(e[i]));
    return w;
  };
  if (s.getNQ() != s.getNU()) return;
  double err = worst();
  for (int it = 0; it < 4 && err > 0; ++it) {
    const auto J = calc_split_jacobian(m, s);
    if (J.G.nrow() != s.getNQErr() || J.G_free.ncol() == 0) return;
    FactorSVD svd(J.G_free);
    Vector rhs = s.getQErr(), dx;
    rhs *= -1.0;
    svd.solve(rhs, dx);
    std::vector<int> q_of_u(s.getNU(), -1);  // each mobilizer's q's and u's pair up (nq = nu)
    for (int b = 0; b < m.matter.getNumBodies(); ++b) {
      const MobilizedBody& mb = m.matter.getMobilizedBody(MobilizedBodyIndex(b));
      if (mb.getNumQ(s) != mb.getNumU(s)) return;
      for (int k = 0; k < mb.getNumU(s); ++k) q_of_u[mb.getFirstUIndex(s) + k] = mb.getFirstQIndex(s) + k;
    }
    const Vector before = s.getQ();
    Vector& q = s.updQ();
    for (size_t c = 0; c < J.free_cols.size(); ++c) {
      if (q_of_u[J.free_cols[c]] < 0) return;
      q[q_of_u[J.free_cols[c]]] += dx[static_cast<int>(c)];
    }
    m.system.realize(s, Stage::Position);
    const double next = worst();
    if (!(next < err)) {  // rounding reached: keep the better configuration
      s.updQ() = before;
      m.system.realize(s, Stage::Position);
      return;
    }
    err = next;
  }
}

void calc_branch_rates(const FullModel::Impl& m, State& s, BranchRates& out) {
  m.system.realize(s, Stage::Position);
  // In place: out's matrices and vectors keep their storage from the previous sample.
  calc_constraint_jacobian(m, s, out.J.G);
  split_jacobian(m, s, out.J);
  out.conditioning = out.J.G.nrow() == 0 ? 1.0 : 0.0;
  out.ls.reset();
  if (out.J.G.nrow() > 0 && out.J.G_free.ncol() > 0) {
    out.conditioning = calc_conditioning(out.J.G_free);
    out.ls.emplace(out.J.G_free);
  }
  const int nu = s.getNU(), ind = m.joint_mobod[m.independent].getFirstUIndex(s);
  out.r.resize(nu);
  out.r = 0.0;
  out.r[ind] = 1.0;
  out.complete(out.r, out.column(ind));
  s.updU() = out.r;
  m.system.realize(s, Stage::Velocity);
  out.b.resize(nu);
  out.b = 0.0;
  if (out.J.G.nrow() > 0) {
    m.matter.calcBiasForAccelerationConstraints(s, out.bias_);
    for (int i = 0; i < out.bias_.size(); ++i) out.bias_[i] = -out.bias_[i];  // −bias, in place
    out.complete(out.b, out.bias_);
  }
}

BranchTangent calc_branch_tangent(const FullModel::Impl& m, State& s, double x) {
  m.set_law(s, 0, poly_law(x, 1.0, 0.0));
  BranchRates rates;
  calc_branch_rates(m, s, rates);
  BranchTangent t;
  t.singular = rates.J.G.nrow() > 0 && rates.J.G_free.ncol() > 0 && rates.conditioning < kSingularConditioning;
  m.matter.multiplyByN(s, false, rates.r, t.dq);
  m.matter.multiplyByN(s, false, rates.b, t.ddq);
  return t;
}

}  // namespace rdyn::engine
