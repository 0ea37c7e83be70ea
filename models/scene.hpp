// Scene: the immutable description of a planar one-degree-of-freedom mechanism.
//
// Plain data, no Simbody. All quantities SI (m, kg, s, rad, N, N·m); every point is
// expressed in its body's frame. Ground frame: x and y span the plane of motion, z
// points out of it; positive rotations are counter-clockwise about z.
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace rdyn::models {

struct Vec2 {
  double x = 0.0;  // [m]
  double y = 0.0;  // [m]
};

// Error in a scene: names the file, and the line and field where there is one.
// The CLI maps it to exit status 2.
class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, int line, std::string field, const std::string& message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }  // 1-based; 0 when unknown
  const std::string& field() const { return field_; }

 private:
  std::string file_;
  int line_;
  std::string field_;
};

// A computation that failed on valid input (an integrator that cannot meet its tolerance or
// its step/wall-time budget, an energy balance that does not close, a non-finite table, a
// calibration that misses its target). The CLI maps it to exit status 1 and writes nothing.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr const char* kGround = "ground";

struct Body {
  std::string name;
  double mass_kg = 0.0;
  Vec2 com_m;                 // centre of mass in the body frame [m]
  double inertia_kgm2 = 0.0;  // centroidal moment of inertia about z [kg·m²]
  std::map<std::string, Vec2> points;  // named points in the body frame [m]
};

enum class JointType { Revolute, Prismatic };

// A tree joint between parent and child. Revolute: q = rotation of the child frame
// relative to the parent frame minus offset_rad (so q = 0 when the child is turned by
// offset_rad). Prismatic: the child translates along `axis` (parent frame) by q, without
// rotating; q = 0 when parent_point and child_point coincide.
struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  std::string parent;
  std::string child;
  Vec2 parent_point;        // joint location on the parent [m]
  Vec2 child_point;         // joint location on the child [m]
  Vec2 axis{1.0, 0.0};      // prismatic only: unit direction in the parent frame
  double offset_rad = 0.0;  // revolute only: child rotation at q = 0 [rad]
  double guess = 0.0;       // starting value for assembly [rad or m]; picks the branch
};

// Loop closure: a point of body_a coincides with a point of body_b (a planar revolute).
struct Loop {
  std::string name;
  std::string body_a;
  Vec2 point_a;
  std::string body_b;
  Vec2 point_b;
};

// Gear: rate(driven) = ratio · rate(driver); both revolute.
struct Gear {
  std::string name;
  std::string driver;  // joint
  std::string driven;  // joint
  double ratio = 1.0;
};

// Sign condition on a joint rate, used to switch a load on and off.
struct RateGate {
  std::string joint;
  int sign = +1;  // load is on while sign · rate(joint) > 0
};

enum class ResistanceLaw { Constant, Viscous, Quadratic };

// Loads. Each one is a generalized force whose work is tracked as non-conservative,
// except springs and gravity, which are potential (V).
struct JointTorque {  // torque on a revolute joint, force on a prismatic one
  std::string name;
  std::string joint;
  double value = 0.0;               // [N·m] or [N], acts on the child, reaction on the parent
  std::optional<RateGate> active_when;
};

// Resistance torque on a body that turns at a fixed ratio to the independent coordinate
// (the crank, or a body geared to it): T = −c0·sgn ω, −c1·ω or −c2·ω|ω|.
struct Resistance {
  std::string name;
  std::string body;
  ResistanceLaw law = ResistanceLaw::Viscous;
  double coefficient = 0.0;  // c0 [N·m], c1 [N·m·s] or c2 [N·m·s²]
};

// Linear spring between two points: F = k (L − L0) along the line.
struct Spring {
  std::string name;
  std::string body_a;
  Vec2 point_a;
  std::string body_b;
  Vec2 point_b;
  double stiffness_N_per_m = 0.0;
  double rest_length_m = 0.0;
};

// Motor torque–speed line on a joint: τ = stall·(1 − rate/no_load_speed).
struct Motor {
  std::string name;
  std::string joint;
  double stall_torque = 0.0;        // [N·m] or [N]
  double no_load_speed = 0.0;       // [rad/s] or [m/s], same sign as stall_torque's motion
};

struct Gravity {
  bool enabled = false;
  Vec2 g_m_s2{0.0, -9.81};
};

// A requested constraint force: the reaction of `joint` on its child along `direction`
// (unit vector in the child frame). Positive pushes the child along +direction.
struct ConstraintForceRequest {
  std::string name;
  std::string joint;
  Vec2 direction;
};

struct Outputs {
  std::vector<ConstraintForceRequest> constraint_forces;
  std::vector<std::string> bodies;  // bodies whose own motion is requested
};

struct Initial {
  double q = 0.0;     // independent coordinate [rad or m]
  double qdot = 0.0;  // [rad/s or m/s]
};

struct Simulation {
  double duration_s = 5.0;
  double output_interval_s = 0.01;
  double tolerance = 1e-9;  // integrator accuracy of the full model (relative)
};

// Acceptance threshold for `rdyn validate`: the reduced model at this grid (and
// interpolation, default the tool's) must reproduce `quantity` ("qdot", a constraint force's
// name — max error over the steady window relative to the peak — or "mean_qdot", the
// relative error of the mean speed) within max_error.
struct Threshold {
  std::string quantity;
  double grid_deg = 10.0;
  std::string interpolation;  // empty: the default
  double max_error = 0.005;
};

// A published value the validation report sets beside rdyn's own (validation.compare).
// `quantity` names a calibration result (kCompareQuantities); the report prints both values,
// the source and the explanation of the difference as the scene gives them.
struct CompareValue {
  std::string quantity;
  double value = 0.0;
  std::string unit, source, explanation;
};
inline const std::vector<std::string> kCompareQuantities{"drive_torque_Nm", "peak_force_N", "speed_fluctuation",
                                                          "mean_power_W"};

struct Validation {
  double duration_s = 0.0;  // 0: simulation.duration_s
  double reference_tolerance = 1e-10;  // full-model reference accuracy (halved to show convergence)
  std::string reference_integrator = "rkmerson";  // rkmerson | rk3 | cpodes
  std::vector<Threshold> thresholds;
  // Calibrate the drive torque so the resistance dissipates power_W at cadence_Hz (0: off).
  double calibrate_cadence_Hz = 0.0;
  double calibrate_power_W = 0.0;
  std::string note;  // why the scene is hard / what it shows (reports quote it)
  std::vector<CompareValue> compare;  // needs calibrate: the values are calibration results
};

struct Scene {
  std::string name;
  std::string source_file;  // where it was read from (for messages)
  std::string description;
  std::vector<Body> bodies;
  std::map<std::string, Vec2> ground_points;
  std::vector<Joint> joints;
  std::vector<Loop> loops;
  std::vector<Gear> gears;
  std::string independent;  // joint name
  std::vector<JointTorque> joint_torques;
  std::vector<Resistance> resistances;
  std::vector<Spring> springs;
  std::vector<Motor> motors;
  Gravity gravity;
  Outputs outputs;
  Initial initial;
  Simulation simulation;
  Validation validation;

  const Body* find_body(const std::string& name) const;
  const Joint* find_joint(const std::string& name) const;
  int joint_index(const std::string& name) const;  // −1 when absent
  int body_index(const std::string& name) const;   // −1 when absent (ground too)
};

// Checks topology and values (tree, one DOF, positive masses, known names...).
// Throws SceneError naming the scene file and the offending field.
void check_scene(const Scene& scene);

// Resistance torque at angular rate ω [rad/s]: −c0·sgn ω, −c1·ω or −c2·ω|ω| [N·m].
double resistance_torque(ResistanceLaw law, double coefficient, double omega);
// Exponent n of the dissipated power P = c·ωⁿ (1 constant, 2 viscous, 3 quadratic).
int dissipation_exponent(ResistanceLaw law);

// Rate of `body` per unit rate of the independent coordinate, when that ratio is a
// constant of the topology: the body is the independent joint's child (ratio 1) or the
// child of a joint geared to it (ratio r). Empty otherwise.
std::optional<double> fixed_speed_ratio(const Scene& scene, const std::string& body);

}  // namespace rdyn::models
