// Scene: the immutable description of a planar one-degree-of-freedom mechanism.
//
// Plain data, no Simbody. All quantities SI (m, kg, s, rad, N, N·m); every point is
// expressed in its body's frame. Ground frame: x and y span the plane of motion, z
// points out of it; positive rotations are counter-clockwise about z.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "models/load_profile.hpp"

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
  const std::string& message() const { return message_; }  // without file, line and field

 private:
  std::string file_;
  int line_;
  std::string field_;
  std::string message_;
};

// A computation that failed on valid input (an integrator that cannot meet its tolerance or
// its step/wall-time budget, an energy balance that does not close, a non-finite table, a
// calibration that misses its target). The CLI maps it to exit status 1 and writes nothing.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A point force's points meet (its line of action has no direction there; the full model stops
// there): `q` the independent coordinate where, `load` the point force. A range table may end
// short of it instead (validate/analysis/build_reduced.cpp): the motion may never get there.
class PointForceMeeting : public NumericalError {
 public:
  PointForceMeeting(const std::string& what, double q_at, std::string load_name)
      : NumericalError(what), q(q_at), load(std::move(load_name)) {}
  double q;
  std::string load;
};

inline constexpr const char* kGround = "ground";

// Ranges every scene value is checked against before any work starts (check_scene and the
// YAML reader; documented in docs/scene-format.md, "Limits"). They bound what a typo can do:
// no NaN/inf, no 1e308 products, no integrator that has to resolve a sub-microsecond time
// constant, no output that fills the disk.
namespace limits {
// Names: [A-Za-z_][A-Za-z0-9_-]{0,63}. They become CSV columns, file names and HTML, and
// '.' separates the parts of a --set key path, so it is not allowed inside a name.
inline constexpr std::size_t kMaxNameLength = 64;
inline constexpr std::size_t kMaxTextLength = 4096;  // description, note [characters]
inline constexpr std::size_t kMaxItems = 1000;  // per list or map: bodies, joints, loads, points...
inline constexpr double kMinMass_kg = 1e-6, kMaxMass_kg = 1e6;
// Lower bounds far below any real part (1 mg; 1e-12 kg·m² is 1 mg at a 1 mm radius of
// gyration), upper bounds far above any machine rdyn models; both far from under/overflow.
inline constexpr double kMinInertia_kgm2 = 1e-12, kMaxInertia_kgm2 = 1e6;
inline constexpr double kMaxCoordinate_m = 1e3;      // |x|, |y| of any point; prismatic q, guess
inline constexpr double kMaxAngle_rad = 1e6;         // |revolute q|, guess, offset (~160 000 turns)
inline constexpr double kMaxRate = 1e4;              // |q̇| [rad/s or m/s]; motor no-load speed
inline constexpr double kMinMotorSpeed = 1e-3;       // |no-load speed| [rad/s or m/s]
inline constexpr double kMaxGravity_m_s2 = 1e3;      // per component (≈ 100 g)
inline constexpr double kMaxForce = 1e6;             // |joint torque| [N·m] or force [N]; |stall|
inline constexpr double kMinGearRatio = 1e-3, kMaxGearRatio = 1e3;  // |ratio|
inline constexpr double kMaxStiffness_N_per_m = 1e9;
// Resistance: the coefficient may not exceed inertia/τ_min of its body (τ_min = 1e-6 s, with
// a reference speed of 1 rad/s for the constant and quadratic laws). For the viscous law
// this bounds the damping time constant of the whole mechanism: m1(q) ≥ I_body·r(q)² (the
// body's own share of the kinetic energy) while the damping on q is c·r(q)², so
// m1/(c·r²) ≥ I_body/c ≥ τ_min whatever the configuration.
inline constexpr double kMinResistanceTimeConstant_s = 1e-6;
inline constexpr double kMaxDuration_s = 1e5;
inline constexpr double kMinOutputInterval_s = 1e-6;
inline constexpr double kMaxOutputRows = 1e7;  // duration / output_interval
inline constexpr double kMinTolerance = 1e-14, kMaxTolerance = 1e-1;
inline constexpr double kMaxReferenceTolerance = 1e-3;  // validation.reference_tolerance
inline constexpr double kMinGrid_deg = 0.05, kMaxGrid_deg = 90.0;
inline constexpr double kMaxCadence_Hz = 20.0;  // dissipates / calibrate cadence
inline constexpr double kMaxPower_W = 1e5;
// A point force's line shorter than this has no direction: refused at assembly (SceneError),
// a run that reaches it stops (NumericalError). 1 µm, far below any muscle or cable.
inline constexpr double kMinPointForceLength_m = 1e-6;
}  // namespace limits

// Whether `name` matches [A-Za-z_][A-Za-z0-9_-]{0,63}.
bool is_valid_name(const std::string& name);
// The message for a name that is not valid (shows it with control characters escaped).
std::string invalid_name_message(const std::string& name);

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

// Assembly branch of a loop: the loop closes with `joint`'s coordinate of this sign (a
// revolute angle wrapped to (−180°, 180°], a prismatic q as it is). Assembly fails, naming the
// loop, when the guesses lead to the other branch, instead of silently simulating it.
struct BranchSign {
  std::string joint;
  int sign = +1;  // +1 positive, −1 negative
};

// Loop closure: a point of body_a coincides with a point of body_b (a planar revolute).
struct Loop {
  std::string name;
  std::string body_a;
  Vec2 point_a;
  std::string body_b;
  Vec2 point_b;
  std::optional<BranchSign> branch;  // empty: the branch the guesses lead to
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
  // Position-dependent drive: the applied load is value·τ(θ_of) (value an amplitude
  // multiplier, 1 unless given), τ a periodic profile of a revolute joint's angle.
  std::optional<LoadProfile> profile = std::nullopt;
};
// The load a joint torque applies now [N·m or N], given the angle of its profile's joint
// (ignored without a profile): value·τ(θ) or value.
inline double calc_joint_torque(const JointTorque& t, double theta_of) {
  return t.profile ? t.value * calc_profile(*t.profile, theta_of) : t.value;
}

// Force between two points, a muscle-like actuator: a tension along the current line from
// point_a (on body_a) to point_b (on body_b), equal and opposite at the two points; positive
// pulls the points together. With a profile the tension is value·τ(θ_of), else value.
struct PointForce {
  std::string name;
  std::string body_a;  // a body or ground
  Vec2 point_a;        // [m] in body_a's frame
  std::string body_b;
  Vec2 point_b;
  double value = 0.0;  // tension [N] (with a profile: amplitude multiplier, 1 unless given)
  std::optional<RateGate> active_when;
  std::optional<LoadProfile> profile;
};
// The tension a point force applies now [N], given the angle of its profile's joint (ignored
// without a profile): value·τ(θ) or value.
inline double calc_point_force_tension(const PointForce& f, double theta_of) {
  return f.profile ? f.value * calc_profile(*f.profile, theta_of) : f.value;
}

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
  // [rad/s] or [m/s]: the rate the motor drives toward, so it has the sign of stall_torque
  // (a motor with opposite signs would push harder the faster it turns and run away).
  double no_load_speed = 0.0;
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
  // Joints whose motion is output (columns q_<j>, qdot_<j>, qddot_<j>; "all" in YAML: every
  // joint, in scene order).
  std::vector<std::string> joints;
  // Joints and loops whose reaction is output: R_<n>_x, R_<n>_y (the joint's force on its child,
  // the loop's force of body_a on body_b, ground frame [N]); prismatic joints add R_<n>_normal
  // [N] and R_<n>_M [N·m] ("all": every joint, then every loop).
  std::vector<std::string> reactions;
  // `reactions: all`: the reduced model's runs give every reaction it can and name the others
  // (reduced::split_reduced_reactions), where a listed reaction it cannot give is refused.
  bool reactions_all = false;
  bool shaking = false;  // shaking_x, shaking_y [N], shaking_M [N·m]: the mechanism's load on the ground
};

struct Initial {
  double q = 0.0;     // independent coordinate [rad or m]
  double qdot = 0.0;  // [rad/s or m/s]
};

// Range of the independent coordinate over which the reduced table spans and both models run
// (scene keys independent_range [rad or m] or independent_range_deg). Absent: a revolute that
// turns fully is periodic; otherwise the range is found from the mechanism's dead points.
struct IndependentRange {
  double min = 0.0;  // [rad or m]
  double max = 0.0;  // [rad or m], > min
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
  // Calibrate a drive load so q turns at a mean cadence_Hz (0: off); with power_W > 0 the one
  // resistance first dissipates power_W at cadence_Hz, with 0 the resistances stay as given.
  double calibrate_cadence_Hz = 0.0;
  double calibrate_power_W = 0.0;
  std::string calibrate_load;  // a joint_torque or motor name; empty: every joint torque together
  // Grid of the calibration's table [deg] (validate; `rdyn calibrate --grid-deg` overrides): a
  // mechanism whose 10° table is too coarse at its operating point (a gear above ~18:1 turns its
  // geared joint 180° per 10° step) is validated there on a finer one.
  double calibrate_grid_deg = 10.0;
  // grid_deg written in the scene (or set): used as it is. Absent: 10°, halved by calibrate,
  // optimize and sweep while the table does not resolve m1 (validate/analysis/build_reduced.hpp).
  bool calibrate_grid_given = false;
  std::string note;  // why the scene is hard / what it shows (reports quote it)
  std::vector<CompareValue> compare;  // needs calibrate: the values are calibration results
};

// The pedalling-strategy search of `rdyn optimize` (scene block `optimize`, docs/scene-format.md):
// which drive loads get a shape τ(θ) = a0 + Σ_k a_k cos kθ + b_k sin kθ of a revolute joint's
// angle, the constraint force whose peak (or p-norm) over the steady cycle it minimises, and the
// bounds. The loads' common amplitude is not designed: it is calibrated per shape.
inline constexpr int kMaxOptimizeHarmonics = 12;
struct OptimizeLoad {
  std::string load;         // a joint torque of the scene
  std::string same_as;      // empty: a shape of its own; else the design load whose shape it takes
  double shift_rad = 0.0;   // with same_as: τ(θ) = τ_same_as(θ − shift) [rad]
};
struct OptimizeSpec {
  std::vector<OptimizeLoad> loads;  // empty: every joint torque, each its own shape
  std::string of;                   // joint whose angle the shapes read; empty: the independent coordinate
  std::string force;                // constraint force to minimise; empty: the first requested
  int harmonics = 3;                // H, [1, kMaxOptimizeHarmonics]
  double max_load = 0.0;            // bound on |value·τ(θ)| [N·m or N]; 0: 5× the calibrated constant value
  bool nonnegative = true;          // τ(θ) ≥ 0 at the sampled angles (the load keeps its sign)
  std::string objective = "peak";   // peak | pnorm
  double p = 8.0;                   // pnorm exponent, [2, 64]
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
  std::optional<IndependentRange> independent_range;  // declared range of the independent coordinate
  std::vector<JointTorque> joint_torques;
  std::vector<Resistance> resistances;
  std::vector<Spring> springs;
  std::vector<Motor> motors;
  std::vector<PointForce> point_forces;
  Gravity gravity;
  Outputs outputs;
  Initial initial;
  Simulation simulation;
  Validation validation;
  std::optional<OptimizeSpec> optimize;  // scene block `optimize` (rdyn optimize)

  // Lines (1-based) of the keys whose checks need the assembled model or a table, so that their
  // refusals name the line too: "independent_range" (or _deg), "initial", "loops.<name>.branch",
  // "validation.calibrate.load", "outputs.reactions", "loads.<point force>.point_b", "loads.<name>". Filled by the YAML reader; where the key
  // came from, not part of the description (not hashed, not written back).
  std::map<std::string, int> key_lines;
  // The same keys when a `--set` override gave their value: key → the override's key path (its
  // line is then 0): a refusal of such a value names the --set argument, not the file's line.
  std::map<std::string, std::string> key_overrides;

  int line_of(const std::string& key) const;  // 0 when unknown
  // The field a refusal of `key` names: "--set <path>" when an override gave it, else `key`.
  std::string field_of(const std::string& key) const;
  const Body* find_body(const std::string& name) const;
  const Joint* find_joint(const std::string& name) const;
  int joint_index(const std::string& name) const;  // −1 when absent
  int body_index(const std::string& name) const;   // −1 when absent (ground too)
};

// Checks topology, names and values (tree, one DOF, known and valid names, every number
// finite and within `limits`). Throws SceneError naming the scene file and the offending
// field: "bodies.<name>.mass_kg" (by name) or "bodies[<i>].name" for a bad name.
void check_scene(const Scene& scene);

// "file:line: field 'key'" (the line when the reader recorded it): how refusals found after
// loading (engine, calibration, reduced reactions) name where the scene says it.
std::string where(const Scene& scene, const std::string& key);

// Resistance torque at angular rate ω [rad/s]: −c0·sgn ω, −c1·ω or −c2·ω|ω| [N·m].
// Inline: the reduced model's right-hand side calls it at every stage (an out-of-line call and
// its switch sat on the RK4 chain's critical path).
inline double resistance_torque(ResistanceLaw law, double c, double w) {
  switch (law) {
    case ResistanceLaw::Constant:
      return w > 0 ? -c : w < 0 ? c : 0.0;
    case ResistanceLaw::Viscous:
      return -c * w;
    case ResistanceLaw::Quadratic:
      return -c * w * (w < 0 ? -w : w);
  }
  return 0.0;
}

// A motor's torque–speed line at its joint's rate u [N·m at rad/s, or N at m/s]: τ_stall (1 − u/u₀),
// u₀ the no-load speed (sign included). The one formula of the full model, the MuJoCo peer and
// the reduced model.
inline double motor_torque(double stall, double no_load_speed, double u) { return stall * (1.0 - u / no_load_speed); }

// A rate gate is open while sign·rate > 0 (RateGate: sign +1 for `rate: positive`, −1 for
// `negative`); at rest it is closed, and the integrators decide the start from the acceleration.
inline bool gate_open(double sign, double rate) { return sign * rate > 0.0; }
// Exponent n of the dissipated power P = c·ωⁿ (1 constant, 2 viscous, 3 quadratic).
int dissipation_exponent(ResistanceLaw law);

// Rate of `body` per unit rate of the independent coordinate, when that ratio is a
// constant of the topology: the body is the independent joint's child (ratio 1) or the
// child of a joint geared to it (ratio r as the driven joint, 1/r as the driver). Empty otherwise.
std::optional<double> fixed_speed_ratio(const Scene& scene, const std::string& body);

// The joint-output columns both models write (timeseries.csv), in this order: per outputs.joints
// q_<j>, qdot_<j>, qddot_<j> [rad or m, /s, /s²]; per outputs.reactions R_<n>_x, R_<n>_y [N]
// (ground frame) and, for a prismatic joint, R_<n>_normal [N] (along the axis turned +90°) and
// R_<n>_M [N·m] (about the child point); then shaking_x, shaking_y [N], shaking_M [N·m] (about
// the ground origin) when outputs.shaking. Validation thresholds may name any of them.
std::vector<std::string> joint_output_names(const Scene& scene);

}  // namespace rdyn::models
