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

// Conditioning of the loop closure at the workspace's configuration: smallest over largest
// singular value of the constraint Jacobian restricted to the mobilities the constraints
// must determine (all but the prescribed ones). Near 0 at a singular configuration
// (e.g. a parallelogram's aligned position), where velocities are not determined; 1 when
// the mechanism has no loop or gear constraint.
double calc_loop_conditioning(const FullModel& model, FullWorkspace& ws);

// Sample of a prescribed time law q(t) = c1 + c2 t + c3 cos(c4 t + c5) at time t (the
// original authors' sweep); same outputs as calc_kinetostatic.
KinetostaticResult calc_harmonic_sweep_point(const FullModel& model, FullWorkspace& ws,
                                             const double c[5], double t, Loads loads);

}  // namespace rdyn::engine
