// Degrees of freedom of an assembled configuration by rank (models/ counts joints and loops, it
// cannot see geometry): the constraint Jacobian restricted to the mechanism's mobilities, its
// rank, the rows that repeat others, and the refusals of a start that is not one degree of
// freedom or sits at a singular configuration.
#include "engine/full_model_impl.hpp"
#include "engine/independent_range.hpp"  // format_coordinate
#include "engine/kinetostatic.hpp"       // kSingularConditioning

#include <cmath>
#include <optional>

#include <fmt/format.h>

namespace rdyn::engine {

using namespace SimTK;
using models::JointType;

namespace {

// Singular values below this fraction of the largest count as zero when ranking the
// constraint Jacobian. Exactly redundant rows (a repeated loop) come out at ~1e-16 relative
// and rows made redundant by an assembled geometry (a parallelogram's third link) at the
// assembly accuracy 1e-12; a loop near an aligned position has σ_min/σ_max ≈ 0.3·(distance
// in rad) (measured on the parallelogram, see reduced_source.cpp), so 1e-9 flags only
// configurations within ~3e-9 rad of a singular one, and those are re-checked nearby.
constexpr double kRankTolerance = 1e-9;
// Above this many constraint rows the row-by-row search for redundant ones (one SVD per row)
// is skipped and only the counts are reported.
constexpr int kMaxRowsToName = 400;

int numerical_rank(const Matrix& A, double tolerance = kRankTolerance) {
  if (A.nrow() == 0 || A.ncol() == 0) return 0;
  FactorSVD svd(A);
  Vector sv;
  svd.getSingularValues(sv);
  if (sv.size() == 0 || !std::isfinite(sv[0])) return 0;
  int r = 0;
  for (int i = 0; i < sv.size(); ++i) r += sv[i] > tolerance * sv[0] ? 1 : 0;
  return r;
}

// Constraint Jacobian ∂(loop and gear conditions)/∂u at a state realized to Position, one
// block per constraint, restricted to the mobilities of the mechanism: the constraint
// actuators' sliders are prescribed to x = 0 and are not degrees of freedom of the scene.
struct Mobility {
  int mobilities = 0;  // columns: joint coordinates of the mechanism
  int rows = 0;        // loop and gear conditions
  int rank = 0;        // of the whole Jacobian
  bool independent_free = true;  // rank unchanged without the independent coordinate's column
  std::vector<std::string> redundant;  // constraints owning a redundant row, "loop 'C' (1 row)"
};

// rank_tolerance: relative, as numerical_rank.
Mobility calc_mobility(const FullModel::Impl& m, const State& s, double rank_tolerance = kRankTolerance) {
  m.system.realize(s, Stage::Position);
  std::vector<bool> keep(s.getNU(), true);
  for (const auto& sl : m.actuator_slider) keep[sl.getFirstUIndex(s)] = false;
  std::vector<int> cols;
  for (int c = 0; c < s.getNU(); ++c)
    if (keep[c]) cols.push_back(c);
  std::vector<Matrix> rows;          // one 1×ncols row per constraint equation
  std::vector<int> owner;            // its constraint
  // The constraints' P blocks are G's rows in constraint order (N = I: engine/constraint_jacobian);
  // Simbody's per-constraint P (calcPositionConstraintMatrixP, one O(n) product per column) cost
  // 4 % of a sweep case. A system the plan does not describe (G then has other rows) keeps it.
  Matrix G;
  calc_constraint_jacobian(m, s, G);
  const bool planned = m.jacobian_plan && G.nrow() == m.jacobian_plan->rows;
  for (size_t k = 0, first = 0; k < m.constraints.size(); ++k) {
    Matrix P;  // mp × nu
    if (planned) {
      const int mp = m.jacobian_plan->line_of[k] >= 0 ? 2 : 1;
      P = G(static_cast<int>(first), 0, mp, G.ncol());
      first += static_cast<size_t>(mp);
    } else {
      P = m.constraints[k].second.calcPositionConstraintMatrixP(s);
    }
    for (int r = 0; r < P.nrow(); ++r) {
      Matrix row(1, static_cast<int>(cols.size()));
      for (size_t c = 0; c < cols.size(); ++c) row(0, static_cast<int>(c)) = P(r, cols[c]);
      rows.push_back(row);
      owner.push_back(static_cast<int>(k));
    }
  }
  auto rank_of = [&](const std::vector<bool>& use, int drop_col) {
    int n = 0;
    for (bool u : use) n += u ? 1 : 0;
    Matrix A(n, static_cast<int>(cols.size()) - (drop_col >= 0 ? 1 : 0));
    for (size_t r = 0, i = 0; r < rows.size(); ++r) {
      if (!use[r]) continue;
      for (int c = 0, o = 0; c < static_cast<int>(cols.size()); ++c)
        if (c != drop_col) A(static_cast<int>(i), o++) = rows[r](0, c);
      ++i;
    }
    return numerical_rank(A, rank_tolerance);
  };
  Mobility out;
  out.mobilities = static_cast<int>(cols.size());
  out.rows = static_cast<int>(rows.size());
  std::vector<bool> use(rows.size(), true);
  out.rank = rank_of(use, -1);
  int indep_col = -1;
  const int indep_u = m.joint_mobod[m.independent].getFirstUIndex(s);
  for (size_t c = 0; c < cols.size(); ++c)
    if (cols[c] == indep_u) indep_col = static_cast<int>(c);
  out.independent_free = rank_of(use, indep_col) == out.rank;
  if (out.rank < out.rows && out.rows <= kMaxRowsToName) {
    // Drop rows from the last declared constraint backwards; a row whose removal keeps the
    // rank repeats what the rows kept impose (for two identical loops, the second one).
    std::vector<int> count(m.constraints.size(), 0);
    for (int r = out.rows - 1; r >= 0; --r) {
      use[r] = false;
      if (rank_of(use, -1) == out.rank) {
        ++count[owner[r]];
      } else {
        use[r] = true;
      }
    }
    for (size_t k = 0; k < m.constraints.size(); ++k)
      if (count[k] > 0)
        out.redundant.push_back(
            fmt::format("{} ({} row{})", m.constraints[k].first, count[k], count[k] > 1 ? "s" : ""));
  }
  return out;
}

// A configuration next to `s` on the same branch: the independent coordinate moved by dq
// and the rest projected onto the constraints. Empty when the projection fails.
std::optional<State> nearby_configuration(const FullModel::Impl& m, const State& s, double dq) {
  State near = s;
  try {
    m.set_law(near, 0, poly_law(m.scene.initial.q + dq, 0.0, 0.0));
    m.system.realize(near, Stage::Time);
    m.system.prescribeQ(near);
    m.system.projectQ(near, 1e-12);
    m.system.realize(near, Stage::Position);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  return near;
}

bool one_dof(const Mobility& mob) {
  return mob.mobilities - mob.rank == 1 && mob.rank == mob.rows && mob.independent_free;
}

}  // namespace

// Degrees of freedom by rank (the counting check in models/ cannot see geometry): the
// mechanism must have mobilities − rank(G) = 1, independent constraint rows (redundant
// ones leave the constraint forces undetermined, Simbody would return one of infinitely
// many splits) and an independent coordinate the constraints do not fix. At an isolated
// singular configuration (aligned links) the rank drops only there, so a deficient
// initial configuration is re-checked 0.01 rad (or 1 mm) to either side before refusing.
void check_one_dof(const FullModel::Impl& m, const State& s) {
  Mobility mob = calc_mobility(m, s);
  if (one_dof(mob)) return;
  const bool rev = m.scene.joints[m.independent].type == JointType::Revolute;
  const double step = rev ? 0.01 : 1e-3;
  bool beside = false;
  for (double dq : {step, -step}) {
    if (const auto near = nearby_configuration(m, s, dq)) {
      const Mobility other = calc_mobility(m, *near);
      // One degree of freedom beside the start but not at it: the start itself is singular.
      if (one_dof(other)) throw_singular_start(m, s);
      if (other.rank > mob.rank) mob = other;
      beside = true;
    }
  }
  // No configuration beside the start could be projected from it (Newton from an exactly flat
  // 10- or 40-loop parallelogram chain fails both ways): where the loop rows are dependent at the
  // extraction's singular threshold, the start is singular and its rank says nothing of the
  // mechanism's count (it reported "cannot move", or 3 degrees of freedom and a redundant loop).
  // An independent coordinate the loops lock has independent rows and keeps its own message.
  if (!beside) {
    const Mobility loose = calc_mobility(m, s, kSingularConditioning);
    if (loose.rank < loose.rows) throw_singular_start(m, s);
  }
  const int dof = mob.mobilities - mob.rank;
  std::string names;
  for (const auto& r : mob.redundant) names += (names.empty() ? "" : ", ") + r;
  const std::string where = fmt::format("{}: at {} = {:.6g} {}", m.scene.source_file, m.scene.independent,
                                        m.scene.initial.q, rev ? "rad" : "m");
  if (dof != 1) {
    throw EngineError(fmt::format(
        "{} the mechanism has {} degrees of freedom: {} joint coordinates, {} of them fixed by the {} loop and gear "
        "conditions (rank of the constraint Jacobian); rdyn needs exactly 1{}",
        where, dof, mob.mobilities, mob.rank, mob.rows,
        names.empty() ? "" : "; redundant (their conditions repeat the others'): " + names));
  }
  if (mob.rank < mob.rows) {
    throw EngineError(fmt::format(
        "{} redundant constraints: {} repeat conditions the other loops and gears already impose (constraint "
        "Jacobian rank {} of {} rows); the constraint forces would not be determined — remove the redundant "
        "loop or link",
        where, names.empty() ? "some rows" : names, mob.rank, mob.rows));
  }
  throw EngineError(fmt::format("{} the independent coordinate '{}' cannot move: the loops and gears fix it (the "
                                "mechanism's one degree of freedom moves other joints only); choose another "
                                "independent joint",
                                where, m.scene.independent));
}

void throw_singular_start(const FullModel::Impl& m, const State& s) {
  // The local count at the singular threshold the extraction uses (kSingularConditioning): an
  // assembly lands ~1e-6 rad from an aligned position (its closure error is quadratic there),
  // where the rank at kRankTolerance is still full. Closer than the assembly's accuracy the rank
  // at that threshold may be full too (the smallest singular value just above it): then the
  // conditioning is what says so, not a "rank 2 of 2".
  const Mobility here = calc_mobility(m, s, kSingularConditioning);
  const bool rev = m.scene.joints[m.independent].type == JointType::Revolute;
  const std::string local =
      here.rank < here.rows
          ? fmt::format("rank {} of {} loop and gear rows over {} joint coordinates, singular values below {:g} of "
                        "the largest dropped: locally {} degrees of freedom, 1 beside it",
                        here.rank, here.rows, here.mobilities, kSingularConditioning, here.mobilities - here.rank)
          : fmt::format("its conditioning is {:.2g}, at the threshold {:g} below which the extraction treats a "
                        "configuration as singular; 1 degree of freedom beside it",
                        calc_loop_conditioning(m, s), kSingularConditioning);
  throw models::SceneError(
      m.scene.source_file, m.scene.line_of("initial"), "initial",
      fmt::format("the mechanism starts at a singular configuration of '{}' ({}): the loop Jacobian loses rank there "
                  "({}) and assembly branches cross there, so neither the branch to follow nor the velocities and "
                  "constraint forces are determined; start it a little away from there",
                  m.scene.independent, format_coordinate(m.joint_q(s, m.independent), rev), local));
}

void calc_mobility_count(const FullModel::Impl& m, const State& s, int& mobilities, int& rows, int& rank) {
  const Mobility mob = calc_mobility(m, s);
  mobilities = mob.mobilities;
  rows = mob.rows;
  rank = mob.rank;
}

}  // namespace rdyn::engine
