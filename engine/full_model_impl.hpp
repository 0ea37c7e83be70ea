// Internal to engine/: the Simbody objects behind FullModel. Includes Simbody.
#pragma once

#include <Simbody.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "engine/constraint_jacobian.hpp"
#include "engine/full_model.hpp"
#include "models/gear_fold.hpp"

namespace rdyn::engine {

// Prescribed law of one coordinate, stored in the State (Stage::Time discrete variable):
// [kind, c1..c5]. kind 0: q = c1 + c2 t + ½ c3 t²  (a kinetostatic point at t = 0: q, q̇, q̈);
// kind 1: q = c1 + c2 t + c3 cos(c4 t + c5)  (the original authors' sweep law).
using Law = SimTK::Vec6;
Law poly_law(double q, double qdot, double qddot);
Law harmonic_law(double c1, double c2, double c3, double c4, double c5);

// Load modes of the SceneLoads force (Stage::Dynamics discrete variable).
enum LoadMode : int {
  kLoadsOff = 0,           // purely inertial (reduced-parameter extraction)
  kLoadsConservative = 1,  // gravity and springs only
  kLoadsInstant = 2,       // everything; rate gates from the instantaneous rate sign
  kLoadsEvents = 3,        // everything; rate gates from flags switched by events
};

// A body reduced onto its driver joint through a gear of ratio r (models/gear_fold.hpp: body,
// driven_joint, driver_joint, ratio, q_offset with q_driven = r·q_driver + q_offset).
using Fold = models::GearFold;

struct FullModel::Impl {
  models::Scene scene;
  FullModelOptions options;
  SimTK::MultibodySystem system;
  SimTK::SimbodyMatterSubsystem matter;
  SimTK::GeneralForceSubsystem forces;

  std::vector<SimTK::MobilizedBody> joint_mobod;  // per scene joint: owner of its coordinate
  std::vector<SimTK::MobilizedBody> body_mobod;   // per scene body
  std::vector<std::optional<Fold>> joint_fold;    // per scene joint
  std::vector<std::optional<Fold>> body_fold;     // per scene body
  // Per constraint force (Actuator route): the prescribed slider along its direction. Requests
  // on one joint form a chain of sliders (massless frames between them) ending at the child.
  std::vector<SimTK::MobilizedBody> actuator_slider;
  std::vector<SimTK::Motion::Custom> actuator_motion;
  SimTK::Motion::Custom independent_motion;
  // Loop closures and unfolded gears, each with the name messages give it ("loop 'C'").
  std::vector<std::pair<std::string, SimTK::Constraint>> constraints;
  std::vector<int> coupled_gears;  // the scene gear of each CoordinateCoupler, in constraint order
  std::vector<bool> gear_coupled;  // per scene joint: the driver or driven joint of a coupler
  // G from the configuration (engine/constraint_jacobian.hpp); none: calcG.
  std::optional<ConstraintJacobianPlan> jacobian_plan;
  int independent = -1;  // scene joint index

  // Where this system's state variables live. Simbody allocates them in its const
  // realizeTopology callbacks (LawMotion, SceneLoads), once per topology realization of this
  // model's own system: a property of the built system, read by every run, never run state
  // (each run's laws, load mode, gates, work and event count are values in its State).
  struct StateIndices {
    std::vector<SimTK::DiscreteVariableIndex> law;  // [0] independent, [1+k] slider k
    SimTK::DiscreteVariableIndex load_mode;
    // Per load slot (joint torques, then point forces: load_gate): its gate flag.
    std::vector<SimTK::DiscreteVariableIndex> gate;
    SimTK::DiscreteVariableIndex events;  // gate switches handled in this State's run
    SimTK::ZIndex work;
  };
  // Owned here, filled by the callbacks through the pointer (the model stays const to runs).
  std::unique_ptr<StateIndices> indices = std::make_unique<StateIndices>();

  // The system's own default State (realizeTopology's, already realized through Model): read in
  // place; a copy held here cost ~0.28 M instructions per built model (a sweep case builds one,
  // issue #28), and every workspace copies it anyway.
  const SimTK::State& default_state() const { return system.getDefaultState(); }

  Impl(const models::Scene& s, FullModelOptions o);

  // Simbody mobilized body of a scene body name (Ground for "ground").
  const SimTK::MobilizedBody& mobod_of(const std::string& body) const;
  // Coordinate and rate of a scene joint (folded joints through their gear).
  double joint_q(const SimTK::State& s, int joint) const;
  double joint_u(const SimTK::State& s, int joint) const;
  // Angular rate of a scene body about z (folded bodies through their gear).
  double body_rate(const SimTK::State& s, int body) const;

  void set_law(SimTK::State& s, int which, const Law& law) const;  // 0 indep, 1+k slider k
  void set_load_mode(SimTK::State& s, LoadMode mode) const;
  void set_gate(SimTK::State& s, int torque, bool on) const;
  bool gate(const SimTK::State& s, int torque) const;
  double work(const SimTK::State& s) const;
  void set_work(SimTK::State& s, double work_J) const;
  long events(const SimTK::State& s) const;  // gate switches handled since the State's start

  // Requested constraint forces at a state realized to Acceleration [N].
  std::vector<double> constraint_forces(const SimTK::State& s) const;
  // Largest loop-closure gap [m] and the loop's name, at a state realized to Position.
  std::pair<double, std::string> worst_loop_gap(const SimTK::State& s) const;
  // Largest gear-coupler residual |q_driven − r·q_driver − c| [rad or m] and the gear's name, from
  // the coordinates (the CoordinateCoupler's own condition; NaN is reported as the worst).
  std::pair<double, std::string> worst_gear_error(const SimTK::State& s) const;
};

struct BranchRates;  // engine/branch_rates.hpp

struct FullWorkspace::Impl {
  const FullModel::Impl& model;
  SimTK::State state;
  // The last two converged configurations (independent coordinate, all q): the secant
  // predictor that starts each projection on the branch being followed.
  double hist_x[2] = {0, 0};
  SimTK::Vector hist_q[2];
  int hist_n = 0;
  // The anchor of calc_kinetostatic_sample's predictor: the last grid point's independent
  // coordinate, all q, and their derivatives along the branch q' and q'' (per unit q̇, q̈ = 0).
  bool anchor_set = false;
  double anchor_x = 0.0;
  SimTK::Vector anchor_q, anchor_dq, anchor_ddq;
  // Projections of this workspace that needed the 1e-9 fallback (a singular configuration): the
  // extraction flags a sample singular when its call raised this.
  long near_singular_projections = 0;
  // calc_kinetostatic_sample's branch rates (engine/branch_rates.hpp), kept from sample to sample
  // so that their matrices and vectors are allocated once per workspace, not per sample.
  std::unique_ptr<BranchRates> sample_rates;
  explicit Impl(const FullModel::Impl& m);  // engine/full_model.cpp, where BranchRates is complete
  ~Impl();
};

// Joint coordinates of the mechanism (constraint actuators' sliders excluded), loop and gear
// condition rows and the rank of their Jacobian, at a state realized to Position
// (engine/mobility.cpp; the same count check_one_dof uses).
void calc_mobility_count(const FullModel::Impl& m, const SimTK::State& s, int& mobilities, int& rows, int& rank);

// Refuses an assembled configuration that is not one degree of freedom by rank (mobilities −
// rank(G) = 1, independent rows, an independent coordinate the constraints do not fix):
// EngineError naming the count or the redundant constraints; throw_singular_start when the rank
// drops only at the start (engine/mobility.cpp).
void check_one_dof(const FullModel::Impl& m, const SimTK::State& s);

// calc_loop_conditioning (kinetostatic.hpp) at a state.
double calc_loop_conditioning(const FullModel::Impl& m, const SimTK::State& s);

// Refuses a start at a singular configuration (the loop Jacobian loses rank there, one degree of
// freedom beside it): models::SceneError naming `initial` and the local degrees of freedom at
// the state (realized to Position or less). The one refusal of the assembly (check_one_dof, so
// every run, inspect included) and of the extraction's first grid point (kinetostatic.cpp).
[[noreturn]] void throw_singular_start(const FullModel::Impl& m, const SimTK::State& s);

// The columns of reduced::joint_output_names (joint motions, reactions, shaking) at a state
// realized to Acceleration (engine/joint_outputs.cpp).
void calc_joint_outputs(const FullModel::Impl& m, const SimTK::State& s, std::vector<double>& out);

// The rate gate of load slot k — joint torque k, then point force k − (joint torques) — or null
// when that load always acts. Slots number the gate flags and the bits of TimeSeries::gates
// (gated loads in slot order), the same order as the reduced model's gates.
const models::RateGate* load_gate(const models::Scene& s, size_t k);
inline size_t num_load_slots(const models::Scene& s) { return s.joint_torques.size() + s.point_forces.size(); }

// Line of a point force at a state realized to Position (`rate` needs Velocity): the points in
// ground [m], their distance L [m], the unit vector e from A to B, and L̇ = e·(v_B − v_A) [m/s].
struct PointForceLine {
  SimTK::Vec3 p_GA, p_GB, e_G;
  double length = 0.0, rate = 0.0;
};
PointForceLine calc_point_force_line(const FullModel::Impl& m, const SimTK::State& s, const models::PointForce& f,
                                     bool with_rate);

// Adds the scene's loads as one custom force (engine/scene_loads.cpp).
void add_scene_loads(FullModel::Impl& impl);
// Generalized power of the non-conservative loads [W] (for the work integral).
double non_conservative_power(const FullModel::Impl& impl, const SimTK::State& s);

}  // namespace rdyn::engine
