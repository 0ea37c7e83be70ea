// Kinetostatic (inverse-dynamics) calls of the full model: the independent coordinate
// is prescribed (q, q̇, q̈), every constraint actuator holds x = ẋ = ẍ = 0, and Simbody
// returns the forces the prescribed motion needs.
#pragma once

#include <vector>

#include "engine/full_model.hpp"

namespace rdyn::engine {

enum class Loads {
  Off,           // purely inertial: reduced parameters m1, m2, me1, me2
  Conservative,  // gravity and springs only
  All,           // every load; rate gates from the sign of the instantaneous joint rate
};

struct KinetostaticResult {
  double driving_force = 0.0;             // T_act: generalized force the driver supplies [N·m or N]
  std::vector<double> constraint_forces;  // F_E per requested constraint force [N]
  std::vector<double> joint_q;            // every scene joint's coordinate [rad or m]
  std::vector<double> joint_u;            // every scene joint's rate [rad/s or m/s]
  double kinetic_energy = 0.0;            // [J]
  double potential_energy = 0.0;          // gravity + springs when loads are on [J]
  std::vector<double> point_force_rate;   // L̇ of every scene point force's line [m/s]
};

// Continues from the workspace's previous configuration (Newton projection), so sweeps
// stay on the assembled branch. Throws EngineError if the configuration cannot be reached
// (dead point, loop that cannot close at this q).
KinetostaticResult calc_kinetostatic(const FullModel& model, FullWorkspace& ws, double q, double qdot,
                                     double qddot, Loads loads);

// Moves the workspace's configuration to q (position projection only): the cheap step of
// continuation sweeps.
void move_configuration(const FullModel& model, FullWorkspace& ws, double q);

// Moves the workspace's configuration to q along the branch it is on (continuation): each move
// starts from the second-order prediction q + q' d + ½ q'' d² (q', q'' from linear solves with the
// loop Jacobian; at a singular configuration, e.g. a parallelogram's aligned position, the chord
// of the last move, as calc_kinetostatic_sample) and projects by Newton's method (projectQ at
// 1e-12, 1e-9 at a singular configuration, when Newton does not contract). A move is at most
// max_step [rad or m] and is halved while Newton corrects the prediction by more than
// max_correction [rad or m] in any coordinate: where two branches pass close and the one followed
// turns sharply, a long move would land on the other. Cost per move: two SVDs of the loop
// Jacobian and 2–4 position realizations. The branch guard of forward dynamics
// (engine/branch_guard.hpp). Throws EngineError when a configuration cannot be reached.
void follow_branch(const FullModel& model, FullWorkspace& ws, double q, double max_step, double max_correction);

// Velocity ratios at q: every joint rate per unit q̇ with every x fixed (wrt_q), and per
// unit ẋ_k with q̇ = 0 and the other x fixed (wrt_x[k]); folded joints through their gear.
struct VelocityRatios {
  std::vector<double> wrt_q;
  std::vector<std::vector<double>> wrt_x;
  // Rate of every point force's length per unit q̇ (dL/dq) and per unit ẋ_k [m per rad or m].
  std::vector<double> length_wrt_q;
  std::vector<std::vector<double>> length_wrt_x;  // [k][point force]
};
// `with_q` / `with_x` select which parts to compute (each part is one velocity projection
// per coordinate).
VelocityRatios calc_velocity_ratios(const FullModel& model, FullWorkspace& ws, double q, bool with_q = true,
                                    bool with_x = true);

// A configuration is singular (its velocities not determined by the constraints) below this
// conditioning: it grows like 0.3 × (distance in rad) from a parallelogram's aligned position.
inline constexpr double kSingularConditioning = 1e-5;

// Conditioning of the loop closure at the workspace's configuration: smallest over largest
// singular value of the constraint Jacobian restricted to the mobilities the constraints
// must determine (all but the prescribed ones). Near 0 at a singular configuration
// (e.g. a parallelogram's aligned position), where velocities are not determined; 1 when
// the mechanism has no loop or gear constraint.
double calc_loop_conditioning(const FullModel& model, FullWorkspace& ws);

// The joint-output columns (models::joint_output_names: joint motions, reactions, shaking) at the
// state the last calc_kinetostatic call left in `ws` — its q, q̇, q̈ and loads — as forward
// dynamics writes them at a row (the inverse-dynamics rows of `rdyn drive`).
std::vector<double> calc_joint_output_row(const FullModel& model, FullWorkspace& ws);

// One grid point of the kinetostatic method from one position projection (Newton, the only
// iterative step) and linear solves with the constraint Jacobian G of that configuration
// (issue #11 item 3). Velocities of call (i) (q̇ = 1, ẋ = 0): r from G r = 0; its accelerations
// (q̈ = ẍ = 0): b = dr/dq from G b = −Ġr; r_x,k (ẋ_k = 1, q̇ = 0) from G r_x,k = 0. Virtual power
// with r and r_x,k (loads off, M u̇ + c + Gᵀλ + τ = 0, actuators supplying −τ) gives call (i),
// m2 = rᵀ(M b + c) and me2_k = r_x,kᵀ(M b + c), and call (ii), where q̇ = 0 makes u̇ = r and the
// bias vanish, m1 = rᵀ M r and me1_k = r_x,kᵀ M r: the same quantities as the separate calls,
// without their projections and forward-dynamics realizations (docs/theory.md §4). Constraint
// forces must use the Actuator route (one prescribed slider each).
struct KinetostaticSample {
  double m1 = 0.0;                           // [kg·m² or kg]
  double m2 = 0.0;                           // ½ dm1/dq [kg·m² or kg/m]
  std::vector<double> me1, me2;              // per constraint force [kg·m or kg]
  std::vector<double> joint_q;               // every scene joint's coordinate [rad or m]
  std::vector<double> ratio_q;               // joint rates per unit q̇, x fixed [joint]
  std::vector<std::vector<double>> ratio_x;  // joint rates per unit ẋ_k, q̇ = 0 [force][joint]
  std::vector<double> ratio_slope;           // d ratio_q / dq [joint]
  std::vector<double> length_wrt_q;          // dL/dq of every scene point force's line (SampleParts::All)
  std::vector<std::vector<double>> length_wrt_x;  // dL/dx_k [force][point force] (SampleParts::All)
  double conditioning = 1.0;                 // as calc_loop_conditioning (SampleParts::All only)
  bool near_singular = false;                // the projection needed its fallback tolerance
};
enum class SampleParts {
  All,        // a grid point: everything above; becomes the anchor of the next prediction
  RatesOnly,  // joint_q, ratio_q and ratio_slope (root finding); the anchor is kept
};
// The projection starts from the anchor (the last grid point of this workspace) extrapolated to
// second order, q_anchor + q' Δ + ½ q'' Δ² (q', q'' from its own realization), when
// |Δ| ≤ max_extrapolation; otherwise from the workspace's configuration, as calc_kinetostatic.
// Throws EngineError when the configuration cannot be reached, NumericalError when a result is
// not finite.
KinetostaticSample calc_kinetostatic_sample(const FullModel& model, FullWorkspace& ws, double q,
                                            double max_extrapolation, SampleParts parts);

// Sample of a prescribed time law q(t) = c1 + c2 t + c3 cos(c4 t + c5) at time t (the
// original authors' sweep); same outputs as calc_kinetostatic.
KinetostaticResult calc_harmonic_sweep_point(const FullModel& model, FullWorkspace& ws,
                                             const double c[5], double t, Loads loads);

}  // namespace rdyn::engine
