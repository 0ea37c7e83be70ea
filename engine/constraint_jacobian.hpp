// The constraint Jacobian G (rows: loop closures and unfolded gears; columns: mobilities) and the
// position errors of the systems rdyn builds, from the configuration alone. Internal to engine/
// (includes Simbody).
#pragma once

#include <Simbody.h>

#include <vector>

#include "engine/full_model.hpp"

namespace rdyn::engine {

// What G needs of a built system, read once from its topology: per mobility (every mobilized
// body is a Pin or a Slider, one u each) its body and u index; per constraint row block the
// mobilities that move its points and with which sign.
struct ConstraintJacobianPlan {
  struct Mobility {
    SimTK::MobilizedBodyIndex body;
    int u = -1, q = -1;
    bool pin = true;   // else a slider
    int parent = -1;   // the parent's mobility, −1 for Ground
    SimTK::Transform X_PF, X_BM;  // the mobilizer's default frames (inboard, outboard)
  };
  // Constraint::PointOnLine: follower point S (on body F) on the line of body L, rows x and y
  // (Simbody's normals: x = line.perp(), y = line × x, fixed in L).
  struct LineRows {
    SimTK::MobilizedBodyIndex line, follower;
    SimTK::Vec3 point_F;       // S in F's frame
    SimTK::Vec3 point_L;       // P, a point of the line, in L's frame
    int line_mobility = -1, follower_mobility = -1;  // −1: Ground
    SimTK::UnitVec3 x_L, y_L;  // row normals in L's frame
    std::vector<std::pair<int, double>> moves;  // (mobility, +1 moves S only, −1 moves L only)
  };
  // Constraint::CoordinateCoupler of a gear q_driven − r q_driver − c = 0: one row.
  struct GearRow {
    int u_driver = -1, u_driven = -1, q_driver = -1, q_driven = -1;
    double ratio = 0.0, offset = 0.0;
  };
  std::vector<Mobility> mobilities;
  // In Simbody's row order (constraint order, each constraint's rows together): entry k is a
  // line block when line_of[k] ≥ 0, else gear gear_of[k].
  std::vector<LineRows> lines;
  std::vector<GearRow> gears;
  std::vector<int> line_of, gear_of;
  int rows = 0, nu = 0;
};

// The plan of a built system, or none when it holds anything else than Pin and Slider mobilizers,
// PointOnLine loops and the gears' couplers (then calc_constraint_jacobian uses calcG).
// The gear rows come from Impl::coupled_gears (the scene gear behind each CoordinateCoupler).
std::optional<ConstraintJacobianPlan> make_constraint_jacobian_plan(const FullModel::Impl& m);

// The plan when it describes the state's rows (its rows and mobilities, every constraint enabled),
// else nullptr (calcG's case). The state must be realized to Instance.
const ConstraintJacobianPlan* usable_plan(const FullModel::Impl& m, const SimTK::State& s);

// G at a state realized to Position: G u = d(perr)/dt for the q̇ = N u of pins and sliders
// (N = I). Per PointOnLine row n·(v_S − v_C) — S the follower point, C the material point of the
// line body at S, n the row's normal rotated with the line body (Simbody's
// calcPositionDotErrors of PointOnLine) — where a unit rate of pin k moves a point p at
// axis_k × (p − pivot_k) and one of slider k at its direction; per gear row ∂perr/∂q: −r at the
// driver, 1 at the driven. The same matrix as SimbodyMatterSubsystem::calcG to rounding
// (tests/engine/constraint_jacobian_test.cpp), which forms each column by a multiplyByPVA
// (~14 k instructions each on the bicycle: 18 % of a sweep case, issue #28). Without a plan, with a
// disabled constraint or rows other than the plan's: calcG itself.
void calc_constraint_jacobian(const FullModel::Impl& m, const SimTK::State& s, SimTK::Matrix& G);

// The position errors perr of the same rows from the coordinates q alone (each body's X_GB =
// X_GP X_PF X_FM(q) X_MB down the tree, X_FM a turn about z or a shift along x; PointOnLine:
// perr = (x, y)·(X_GL⁻¹ p_S − P), gears: q_driven − r q_driver − c), without realizing a
// State: Simbody's Position realization (every body, cache and constraint, ~28 k instructions on
// the bicycle) was the chord Newton projection's main cost. Equal to the state's QErr to rounding
// (tests/engine/constraint_jacobian_test.cpp); callers accept a configuration only on Simbody's
// own errors.
void calc_constraint_errors(const ConstraintJacobianPlan& plan, const SimTK::Vector& q, SimTK::Vector& perr);

// The errors and G together from the coordinates alone: G as calc_constraint_jacobian forms it,
// with the frames of calc_constraint_errors instead of a realized State's. The chord Newton
// projection's Jacobian at its starting configuration, which needed a Position realization for
// nothing else (~28 k instructions on the bicycle, 1.3 M of a sweep case's 30 M, issue #28).
// Equal to calcG at the realized configuration to rounding (tests/engine/constraint_jacobian_test.cpp).
void calc_constraint_errors_and_jacobian(const ConstraintJacobianPlan& plan, const SimTK::Vector& q,
                                         SimTK::Vector& perr, SimTK::Matrix& G);

}  // namespace rdyn::engine
