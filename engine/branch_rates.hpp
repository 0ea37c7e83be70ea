// Internal to engine/: rates along the assembly branch from the loop Jacobian — the one route to
// the velocity ratios r, their slope b = dr/dq and the branch's tangent (the kinetostatic sample,
// the branch continuation and the singular passage use it) — and the position projections they
// need. Includes Simbody.
#pragma once

#include <optional>
#include <vector>

#include "engine/full_model_impl.hpp"
#include "engine/least_squares.hpp"

namespace rdyn::engine {

// The constraint Jacobian G (loop and unfolded gear rows × mobilities) at a state realized to
// Position, split into the columns of the mobilities the constraints determine (`free`: all but
// the independent coordinate and the constraint actuators) and G itself.
struct SplitJacobian {
  SimTK::Matrix G, G_free;
  std::vector<int> free_cols;
};
SplitJacobian calc_split_jacobian(const FullModel::Impl& m, const SimTK::State& s);

// A scene joint's component of a mobility-space vector (folded joints through their gear).
double joint_part(const FullModel::Impl& m, const SimTK::State& s, const SimTK::Vector& u, int j);

// The chord Newton projection alone, from the state's configuration with the prescribed
// coordinates as they are (realized to Time and prescribed by the caller): true when every loop
// closes to 1e-13, the errors halving at each of at most 8 iterations; false — the state then
// holds the last iterate — otherwise (nq ≠ nu, a singular configuration, a start too far).
bool newton_project(const FullModel::Impl& m, SimTK::State& s);

// Position projection with the independent coordinate prescribed: a chord Newton iteration with
// the predicted configuration's Jacobian, else Simbody's projectQ at 1e-12, else at 1e-9 (a
// singular configuration, counted in the workspace). Throws what projectQ throws when none
// succeeds (the callers name the coordinate).
void project_prescribed(FullWorkspace::Impl& w);

// Near a singular configuration the rates carry the loop residual magnified by the
// conditioning κ: positions by 1/κ, velocity ratios by 1/κ², m2 (second-order terms) by 1/κ³;
// a residual of 1e-13 put m2 off by 1e-6 at 4e-3 rad from a parallelogram chain's flat
// configuration. Where κ < kPolishConditioning (regular mechanisms stay above: the bicycle
// 0.06, the hard high-saddle 0.0075; a chain's samples 4e-3 rad from flat 5e-4…2e-3), full
// Newton steps (a fresh Jacobian each) drive the residual down to rounding: at most 4, kept only
// while the residual falls.
inline constexpr double kPolishConditioning = 5e-3;
void polish_projection(const FullModel::Impl& m, SimTK::State& s);

// The branch's rates at a configuration realized to Position whose independent law gives q̇ = 1
// (kinetostatic mode): r (q̇ = 1, ẋ = 0) from G_free r_free = −G e_independent, and b = dr/dq (the
// accelerations at q̈ = ẍ = 0) from G_free b_free = −bias (Simbody: acceleration constraint errors
// G u̇ + bias, bias = −Ġu at this velocity); least squares: G may carry redundant rows, the system
// is consistent. Leaves u = r in the state, realized to Velocity; J and its factorization stay for
// further solves (calc_kinetostatic_sample's r_x,k). The one route to r and b (the sample, follow_branch).
// `out` may hold an earlier configuration's rates: every field is overwritten (its storage reused).
struct BranchRates {
  SplitJacobian J;
  // calc_conditioning of J.G_free: 1 without rows, 0 with rows but no free columns.
  double conditioning = 1.0;
  std::optional<LeastSquares> ls;  // of J.G_free, for the solves (one decomposition for all)
  SimTK::Vector r, b;                   // [mobilities]
  // v: prescribed entries set; the free ones solved from G_free v_free = rhs.
  void complete(SimTK::Vector& v, const SimTK::Vector& rhs) {
    if (!ls) return;
    ls->solve(rhs, x_);
    for (size_t c = 0; c < J.free_cols.size(); ++c) v[J.free_cols[c]] = x_[static_cast<int>(c)];
  }
  // −(column col of G): the right-hand side for a unit rate of prescribed mobility col, in a
  // scratch vector that the next call overwrites.
  const SimTK::Vector& column(int col) {
    rhs_.resize(J.G.nrow());
    for (int r = 0; r < J.G.nrow(); ++r) rhs_[r] = -J.G(r, col);
    return rhs_;
  }
  // Scratch of complete(), column() and calc_branch_rates (the bias): a BranchRates reused from
  // sample to sample (the workspace's) allocates none of its vectors again — a SimTK::Vector
  // costs ~1 k instructions to build and free, and a sample built ~15 (issue #28).
  SimTK::Vector x_, rhs_, bias_;
};
void calc_branch_rates(const FullModel::Impl& m, SimTK::State& s, BranchRates& out);

// The branch's derivatives at a configuration: q' = N r and q'' = N b per unit of the
// independent coordinate (Ṅ = 0 for the pins and sliders rdyn builds); `singular` when the loop
// Jacobian's conditioning is below kSingularConditioning (r, b are then least-squares values of
// no particular branch).
struct BranchTangent {
  SimTK::Vector dq, ddq;
  bool singular = false;
};
BranchTangent calc_branch_tangent(const FullModel::Impl& m, SimTK::State& s, double x);

}  // namespace rdyn::engine
