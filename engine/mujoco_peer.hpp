// MuJoCo as a peer engine (issue #11): the scene exported as MJCF (models/mjcf_export.hpp),
// loaded from memory, its loads applied at every evaluation with the full model's formulas
// (engine/scene_loads.cpp), integrated at a fixed time step with MuJoCo's semi-implicit Euler or
// RK4. No Simbody here. Optional at build time: without MuJoCo (CMake found no libmujoco and
// mujoco/mujoco.h) mujoco_available() is false and MujocoModel throws EngineError.
//
// Differences from the full model, by construction: loop closures and gears are MuJoCo's soft
// equality constraints (solref/solimp; the loop closes to a small gap that shrinks with the time
// step), rate-gated loads switch at the first evaluation past the crossing (no event location),
// geared bodies are folded into their drivers as the full model does (calc_foldable_gears).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/full_model.hpp"
#include "models/scene.hpp"
#include "models/timeseries.hpp"

namespace rdyn::engine {

// Whether rdyn was built with MuJoCo; its version ("2.2.2") or "".
bool mujoco_available();
std::string mujoco_version();

struct MujocoSettings {
  double timestep_s = 1e-3;          // fixed step [s], > 0
  std::string integrator = "euler";  // euler (MuJoCo's semi-implicit Euler) | rk4
  // Equality softness (models::MjcfOptions): solref timeconst (0: twice the step, the smallest
  // MuJoCo's `refsafe` accepts) and solimp dmin = dmax.
  double timeconst_s = 0.0;
  double impedance = 0.9999;
};

// The compiled MuJoCo model of a scene (immutable once built). `initial_q` holds every scene
// joint's coordinate at the start (an assembled configuration: MuJoCo infers each loop's second
// anchor from it). Throws EngineError when MuJoCo is absent, a setting is out of range, or
// MuJoCo refuses the model (its message).
class MujocoModel {
 public:
  MujocoModel(const models::Scene& scene, const std::vector<double>& initial_q, const MujocoSettings& settings);
  ~MujocoModel();
  MujocoModel(const MujocoModel&) = delete;
  MujocoModel& operator=(const MujocoModel&) = delete;
  const MujocoSettings& settings() const;
  const std::string& mjcf() const;  // the document it was compiled from

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

struct MujocoRunOptions {
  double duration_s = 5.0;          // (0, ∞) [s]
  double output_interval_s = 0.01;  // a whole number of time steps [s]
  std::vector<double> initial_u;    // every scene joint's rate at the start (consistent with q)
  long max_steps = 50'000'000;      // duration / step may not exceed this
  double max_wall_s = 600.0;        // checked at every output [s]
};

// Time step that fills `output_interval_s` with a whole number of steps, at most `step_s`.
double calc_peer_step(double step_s, double output_interval_s);

// Starts from the model's initial q and options.initial_u; records t, q, q̇, q̈ of the independent
// coordinate, the requested constraint forces (the reaction of the joint on its child: the force
// part of mj_rnePostConstraint's cfrc_int, projected on the direction), kinetic + potential energy
// and the work of the non-conservative loads (integrated with the integrator's own weights), at
// every output time. Throws EngineError for options out of range and models::NumericalError when
// MuJoCo's motion becomes non-finite, or a budget is exhausted.
models::TimeSeries simulate_mujoco(const MujocoModel& model, const MujocoRunOptions& options);

}  // namespace rdyn::engine
