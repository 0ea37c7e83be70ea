// The small interface through which reduced/ asks a full model for kinetostatic
// (inverse-dynamics) answers. engine/ implements it on Simbody; tests implement it on
// analytic mechanisms. No Simbody here.
#pragma once

#include <optional>
#include <utility>
#include <vector>

namespace rdyn::reduced {

// Forces a prescribed motion needs (applied loads as requested by the call).
struct ForcePoint {
  double driving_force = 0.0;             // T_act on the independent coordinate [N·m or N]
  std::vector<double> constraint_forces;  // F_E per constraint actuator [N]
  std::vector<double> joint_rates;        // every joint's rate in this call (optional) [rad/s or m/s]
};

// Static call (q̇ = q̈ = 0) with only the conservative loads (gravity, springs) on.
struct ConservativePoint {
  ForcePoint forces;
  double potential_energy = 0.0;  // V(q) [J]
};

// Joint rates per unit q̇ (every x fixed) and per unit ẋ_k (q̇ = 0): virtual power ratios.
struct RatioPoint {
  std::vector<double> wrt_q;               // [joint]
  std::vector<std::vector<double>> wrt_x;  // [constraint force][joint]
  // Every joint's coordinate at this q (optional: empty when the source does not give it; the
  // joint-output columns p_<joint> need it) [rad or m].
  std::vector<double> joint_q;
  // d(wrt_q)/dq per joint (optional: empty when the source does not give it; root finding of
  // switch angles then uses Brent's method on `ratio`) [rad/rad², m/m² …].
  std::vector<double> wrt_q_slope;
  // Rate of each scene point force's length per unit q̇ (dL/dq) and per unit ẋ_k (optional:
  // empty when the source does not give them; point forces need them) [m per rad or m].
  std::vector<double> length_wrt_q;
  std::vector<std::vector<double>> length_wrt_x;  // [constraint force][point force]
};

// The cross-check of issue 3, route "direct": m1 = uᵀMu, me1 = u_xᵀMu, m2 = uᵀ(M b + c),
// me2 = u_xᵀ(M b + c), from the mass matrix and bias forces.
struct DirectPoint {
  double m1 = 0.0, m2 = 0.0;
  std::vector<double> me1, me2;
};

// Everything the kinetostatic method needs at one grid point, gathered in one visit.
struct GridSample {
  ForcePoint velocity;      // (i) q̇ = 1, q̈ = 0, loads off
  ForcePoint acceleration;  // (ii) q̇ = 0, q̈ = 1, loads off
  ConservativePoint conservative;  // zero when not requested
  RatioPoint ratios;
  // The configuration is singular (the loop Jacobian lost rank): velocities and forces there
  // are not determined by the constraints, so the sample is not trustworthy.
  bool singular = false;
  // The loop Jacobian's conditioning there (smallest over largest singular value of its free
  // columns; 1 without loops), when the source gives it; near rank loss it falls like the
  // distance to it. The extraction looks for rank loss between grid points where it is small.
  double conditioning = 1.0;
};

class KinetostaticSource {
 public:
  virtual ~KinetostaticSource() = default;
  virtual int num_constraint_forces() const = 0;
  virtual int num_joints() const = 0;
  // Inverse dynamics with every applied load off (purely inertial).
  virtual ForcePoint inertial(double q, double qdot, double qddot) = 0;
  virtual ConservativePoint conservative(double q) = 0;
  virtual RatioPoint ratios(double q) = 0;
  // Optional routes; empty when the source cannot offer them.
  // A sample of the prescribed law q(t) = c1 + c2 t + c3 cos(c4 t + c5) at time t,
  // continuing from the previous sample (applied loads off).
  virtual std::optional<ForcePoint> harmonic_sweep(const double c[5], double t) {
    (void)c, (void)t;
    return std::nullopt;
  }
  virtual std::optional<DirectPoint> direct(double q) {
    (void)q;
    return std::nullopt;
  }
  // One grid point. The default makes the separate calls; a source may share work between
  // them (the engine takes the q-ratios from call (i), where q̇ = 1).
  virtual GridSample sample(double q, bool with_conservative) {
    GridSample g;
    g.velocity = inertial(q, 1.0, 0.0);
    g.acceleration = inertial(q, 0.0, 1.0);
    if (with_conservative) g.conservative = conservative(q);
    else g.conservative.forces.constraint_forces.assign(num_constraint_forces(), 0.0);
    g.ratios = ratios(q);
    return g;
  }
  // Rate of one joint per unit q̇ at q (root finding of switch angles).
  virtual double ratio(double q, int joint) { return ratios(q).wrt_q[joint]; }
  // The same with its slope d(rate)/dq at q, for Newton's method; empty when the source
  // cannot give slopes.
  virtual std::optional<std::pair<double, double>> ratio_and_slope(double q, int joint) {
    (void)q, (void)joint;
    return std::nullopt;
  }
  // Coordinate of one joint at q [rad or m] on the branch the sweep follows (the angle a
  // profiled drive load reads). Empty when the source cannot give positions.
  virtual std::optional<double> joint_coordinate(double q, int joint) {
    (void)q, (void)joint;
    return std::nullopt;
  }
};

}  // namespace rdyn::reduced
