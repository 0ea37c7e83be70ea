// The reduced model: an immutable fused table plus the scene's loads expressed through it,
// and a small workspace for stepping. No Simbody.
//
//   Eksergian:        m1(q) q̈ + m2(q) q̇² = F*(q, q̇, t)
//   constraint line:  me1_k(q) q̈ + me2_k(q) q̇² = F*_x,k = F_E,k + Q_x,k(loads)
//
// F* = Q_cons(q) + Σ torques T·[τ(q)]·r_j(q)·[gate] + Σ motors τ(r_j q̇)·r_j + Σ brakes T(w_b q̇)·w_b
//      + Σ point forces T·[τ(q)]·(−dL/dq)·[gate]
// (virtual power), and likewise Q_x,k with the ratios along x_k.
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "reduced/samples.hpp"
#include "reduced/table.hpp"

namespace rdyn::reduced {

struct ReducedModel {
  Table table;
  // Range tables: what ends the validity domain at each edge ("dead point", "declared limit",
  // empty when the table does not say) and the coordinate's kind, for the stop message.
  std::string min_edge, max_edge;
  bool revolute = true;
  std::vector<std::string> force_names;
  int c_m1 = -1, c_m2 = -1, c_V = -1, c_Q = -1;
  std::vector<int> c_me1, c_me2, c_Qx;  // per constraint force
  // Per constraint force: the singular configurations where its columns have a pole (Samples::
  // poles), and the half-width around them where its interpolated value is not trusted [rad or m].
  std::vector<std::vector<double>> force_poles;
  double pole_band = 0.0;

  // Load on while sign · r(q) · q̇ > 0. When the table carries the exact zeros ρ_k of r
  // (located on the full model), the switching function uses c·Π sin((q − ρ_k)/2) instead of
  // the interpolated r: same sign, zero exactly at the switch angles.
  struct Gate {
    int c_r = -1;
    int sign = +1;
    std::vector<double> roots;
    double root_sign = 1.0;  // c
    // The roots taken two by two (ρ_a, ρ_b), as sin((q−ρ_a)/2)·sin((q−ρ_b)/2) =
    // ½[cos((ρ_a−ρ_b)/2) − cos(q − (ρ_a+ρ_b)/2)]: one cosine per pair instead of two sines (the
    // sines were a quarter of a fixed-step run's time). Pairs closer than 1e-3 rad, where the
    // difference of cosines would cancel, and roots set without pairs use the product itself.
    struct RootPair {
      double cos_half_gap = 0.0, mid = 0.0;
      double half_gap = 0.0;  // acos(cos_half_gap) ∈ [0, π]: the factor is > 0 where |wrap(q − mid)| > half_gap
    };
    std::vector<RootPair> pairs;  // filled by set_gate_roots; empty: the product of sines
  };
  struct Torque {
    double value = 0.0;   // [N·m or N]
    int c_r = -1;         // ratio of its joint
    std::vector<int> c_rx;
    int gate = -1;        // index into gates, −1 when always on
    int c_tau = -1;       // profiled load: column tau_<load>, τ(θ_of(q)) per unit value; −1 constant
  };
  struct Motor {
    double stall = 0.0, no_load_speed = 0.0;
    int c_r = -1;
    std::vector<int> c_rx;
  };
  struct Brake {
    models::ResistanceLaw law = models::ResistanceLaw::Viscous;
    double coefficient = 0.0;
    int c_w = -1;
    std::vector<int> c_wx;
  };
  std::vector<Gate> gates;  // gated joint torques, then gated point forces (the full model's slot order)
  std::vector<Torque> torques;
  // Point forces, as torques whose "ratio" is the generalized force per unit tension: c_r the
  // column Qpf_<load> (−dL/dq), c_rx the Qxpf_<k>_<load> columns; value the tension [N] (no
  // runtime drive command changes it; calibration sets it here).
  std::vector<Torque> point_forces;
  std::vector<Motor> motors;
  std::vector<Brake> brakes;

  // Columns the right-hand side needs, in this order: m1, m2, Q_cons, then each torque's r
  // (and its tau when profiled), each motor's r, each brake's w, each point force's Qpf (and tau),
  // and last V (for calc_acceleration_energy).
  std::vector<int> rhs_cols;
  // Columns the outputs need (one fused lookup): m1, V, then per constraint force k:
  // me1, me2, Qx_cons, each torque's rx (and tau), each motor's r and rx, each brake's w and wx,
  // each point force's Qxpf (and tau).
  std::vector<int> out_cols;
  std::vector<int> record_cols;  // rhs_cols then out_cols: one lookup per output sample
  // rhs_cols and record_cols packed for one fused evaluation each (table.hpp, ColumnBlock).
  ColumnBlock rhs_block, record_block;
};

// Joins the sampled parameters with the scene's loads. Throws TableError when the samples were
// extracted from another scene (their scene_hash differs from models::scene_hash(scene), or they
// record none), when a column the loads need is missing, or when the interpolated m1 is not
// positive.
ReducedModel make_reduced_model(const Samples& samples, const models::Scene& scene, Interpolation interp,
                                bool energy_consistent_m2 = false);

// The same with the table already built from these samples (build_table(samples, …)): scenes
// that differ only in what the scene hash leaves out (load values, resistance coefficients)
// share one table; each gets its own loads. Throws as above.
ReducedModel make_reduced_model(const Samples& samples, const models::Scene& scene, Table table);

// The columns make_reduced_model(samples, scene, …) reads for `scene`'s constraint forces and
// loads, each once, in the order it asks for them. A model built on select_columns(samples, these)
// (reduced/samples.hpp) is the model of all the samples, value for value: what a sweep fits.
std::vector<std::string> reduced_model_columns(const models::Scene& scene);

// Per-run state: the ODE state, the load gates, and scratch space sized once.
struct ReducedWorkspace {
  double t = 0.0, q = 0.0, qdot = 0.0, work = 0.0;
  std::vector<char> gate_on;
  // Each scene joint torque as applied now [N·m or N]: the scene's values, unless a drive
  // command (reduced/runtime.hpp) scales or overrides them during the run.
  std::vector<double> torque_value;
  std::vector<double> scratch;      // rhs_cols values
  std::vector<double> scratch_out;  // out_cols values
  std::vector<double> scratch_rec;  // record_cols values
  // The gates' switching functions at (switching_q, switching_qdot): a fixed step starts where
  // the last one ended, so its start values are the last end values (reduced/simulate_reduced).
  std::vector<double> switching;
  double switching_q = NAN, switching_qdot = NAN;
  // Fixed-step RK4 with predictable gates (every gate's switch angles known): at the state
  // (ahead_q, ahead_qdot) with the gates ahead_gates (bit g: gate g on), the gates agree with
  // their switching functions and no switch angle lies strictly between q and ahead_limit in
  // the direction of q̇. A step that stays short of it needs neither the switch prediction nor
  // the check at its end (step_fixed_rk4).
  double ahead_q = NAN, ahead_qdot = NAN, ahead_limit = NAN;
  unsigned ahead_gates = 0;
  explicit ReducedWorkspace(const ReducedModel& m);
};

// q̈ and the power of the non-conservative loads at (q, q̇) with the workspace's gates.
// Allocation-free.
void calc_acceleration(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double& qddot,
                       double& power_nc);

// calc_acceleration, and the energy ½ m1 q̇² + V at (q, q̇) from the same table lookup [J] (the
// same value as calc_energy).
double calc_acceleration_energy(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double& qddot,
                                double& power_nc);

// Switching function of gate g: its sign decides whether the gated load acts.
double calc_switching(const ReducedModel& m, int gate, double q, double qdot);

// Every gate's switching function at (q, q̇) into ws.switching, reusing the values when the
// workspace last evaluated them at the same state.
const double* calc_switching_all(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot);

// Sets a gate's exact switch angles and their pairs (ReducedModel::Gate::pairs).
void set_gate_roots(ReducedModel::Gate& gate, std::vector<double> roots);

// Sets every gate from the state (from rest: from the sign of the acceleration the load
// would produce, as the full model does).
void init_gates(const ReducedModel& m, ReducedWorkspace& ws);

// Kinetic + potential energy ½ m1 q̇² + V at (q, q̇) [J].
double calc_energy(const ReducedModel& m, double q, double qdot);
// Everything an output sample needs — q̈, non-conservative power, energy and the constraint
// forces F_E,k = me1_k q̈ + me2_k q̇² − Q_x,k [N] — from one fused table lookup
// (allocation-free). Returns the energy. The one implementation of the constraint-force
// algebra: simulate_reduced's rows and the runtime's outputs both come from it.
double calc_sample(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double& qddot,
                   double& power_nc, double* forces);

// Throws NumericalError when q lies within m.pole_band of a pole of a constraint force (no
// interpolation of me1, me2 and Q_x represents a pole: an isosceles slider-crank's rod force
// came out 0.23 N where the full model gives 28.4 N, and 1.7 % off four grid steps away). Called
// for every output row of simulate and drive; `t` names the row. A reaction's internal line is
// named as its joint's reaction (reduced/force_poles.cpp).
void check_force_poles(const ReducedModel& m, double q, double t);

// Prescribed motion, the inverse form of Eksergian's equation: the generalized force a drive on
// q must add for the mechanism to follow (q, q̇, q̈) under the model's loads,
//   drive = m1 q̈ + m2 q̇² − F*(q, q̇) = m1 (q̈ − q̈_free(q, q̇)),
// and the constraint forces F_E,k = me1_k q̈ + me2_k q̇² − Q_x,k at that q̈ (the drive acts on q
// alone, so it enters no constraint line; docs/theory.md, "Prescribed motion"). Gates follow the
// sign of the prescribed rate (of q̈ where q̇ = 0). Returns the drive [N·m or N]; `power_nc`
// gets the loads' power F_nc q̇ [W]. Allocation-free.
double calc_drive(const ReducedModel& m, ReducedWorkspace& ws, double q, double qdot, double qddot, double& power_nc,
                  double* forces);

// Divergence guard of the reduced integrators, the same in simulate_reduced, the runtime and
// the C API. The reduced equation's own energy balance E − E0 = W (W: work of the
// non-conservative loads) holds to interpolation accuracy; a residual above half the energy
// scale means the table or the step is too coarse for the run to be stable. The scale must be
// one the divergence cannot inflate and that does not depend on where V's zero lies (a guard
// against half the largest |E| seen let a fixed-step run gain 20× its kinetic energy with exit
// 0 when V was large, since the divergence itself raised |E|): the energy the run started with
// above the table's lowest potential, E0 − min V ≥ ½ m1(q0) q̇0², plus the largest |W| so far.
// On a correct run W = E − E0 stays within the energy range the motion visits (a steady cycle
// repeats it); energy a coarse step injects and a brake then dissipates makes W drift by the
// residual itself, so the guard fires once the error reaches the scale of the motion's energy.
// (A sum of |ΔW| per step, tried first, grew with every cycle of a driven, braked run: a light
// flywheel 14 rad off after 30 s at 0.1 s steps passed with a residual 3.7× its energy.)
struct DivergenceGuard {
  double energy0 = 0.0;    // E0 [J or N·m]
  double scale0 = 0.0;     // E0 − min V over the table's grid
  double work_max = 0.0;   // largest |W| so far
};
// Lowest potential over the table's grid points (the interpolant's nodes).
double calc_potential_min(const ReducedModel& m);

// "q = 12.5°" or "q = 0.031 m" (`digits` significant): messages give q in the unit users type.
std::string describe_q(bool revolute, double q_rad_or_m, int digits = 9);
DivergenceGuard start_divergence_guard(double energy0, double potential_min, double work0);
// Updates the largest |W| and returns true when |E − E0 − W| exceeds half the scale.
inline bool divergence_guard_fires(DivergenceGuard& g, double E, double work) {
  g.work_max = std::max(g.work_max, std::abs(work));
  const double residual = std::abs(E - g.energy0 - work);
  return !(residual <= 0.5 * (g.scale0 + g.work_max) + 1e-9 * (1.0 + std::abs(g.energy0)));
}

// One fixed RK4 step of size h for real-time use, allocation-free; a gate switch inside
// the step splits it there (at most 8 splits; the step always advances t by h). A gate whose
// switch angles are known (Gate::pairs) has its switch predicted before the step, from the
// Taylor path q0 + q̇0 τ + ½ q̈0 τ² meeting a switch angle: the step is cut at that τ without
// first taking the whole step; the switch is made only where the step reached the angle. This
// needs every gate's angles; a model with a gate without them, and any switch the prediction
// does not see (q̇ changing sign), are located after the step by linear interpolation of the
// switching function.
// Returns the time of the first switch, or NaN when none happened.
double step_fixed_rk4(const ReducedModel& m, ReducedWorkspace& ws, double h);
// The same with the start derivative k1 = (q̈, power) at (ws.q, ws.q̇) under ws's gates when
// the caller has it already (simulate_reduced keeps each step's end point): one right-hand
// side fewer per step, the same numbers. k1 may be null.
double step_fixed_rk4(const ReducedModel& m, ReducedWorkspace& ws, double h, const double* k1);

}  // namespace rdyn::reduced
