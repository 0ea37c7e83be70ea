// Full multibody model of a scene, built on Simbody (kept behind this header: no Simbody
// type appears here). A FullModel is the immutable description (the Simbody system); a
// FullWorkspace is the per-run state (configuration, continued from call to call).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "models/scene.hpp"

namespace rdyn::engine {

// How requested constraint forces are computed.
//  Actuator: the joint becomes a pin plus a slider along the requested direction whose
//            coordinate x is prescribed to stay 0 (the paper's "constraint actuator");
//            F_E = −τ_x, Simbody's motion multiplier.
//  Reaction: plain pin; F_E = Simbody's mobilizer reaction projected on the direction.
enum class ConstraintForceRoute { Actuator, Reaction };

struct FullModelOptions {
  ConstraintForceRoute route = ConstraintForceRoute::Actuator;
  // Reduce a geared body whose own motion is not requested onto its driver
  // (inertia r²·I), instead of simulating it as its own body with a gear constraint.
  bool fold_geared_bodies = true;
};

// Failure of the engine on a valid scene (loop cannot close, dead point reached...).
class EngineError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FullModel {
 public:
  // Builds and realizes the Simbody system. Throws EngineError.
  explicit FullModel(const models::Scene& scene, FullModelOptions options = {});
  ~FullModel();
  FullModel(const FullModel&) = delete;
  FullModel& operator=(const FullModel&) = delete;

  const models::Scene& scene() const;
  const FullModelOptions& options() const;
  // Bodies simulated as Simbody bodies (folded ones excluded).
  int num_simbody_bodies() const;
  bool is_folded(const std::string& body) const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Per-run workspace: a Simbody state assembled on the scene's branch. Kinetostatic calls
// continue from the previous configuration (Newton projection, no fresh assembly).
class FullWorkspace {
 public:
  // Assembles at the scene's initial q. Throws EngineError naming the loop that cannot
  // close and its gap in metres.
  explicit FullWorkspace(const FullModel& model);
  ~FullWorkspace();
  FullWorkspace(FullWorkspace&&) noexcept;

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// An exception's text for a user, for the engine's messages: Simbody's texts lose their source
// file, line and boilerplate ("SimTK Exception thrown at Integrator.cpp:…:", "Required
// condition 't1 > t0' was not met") and come on one line, what failed in words, the checked
// condition as a hint; the integrator's zero-length event interval (t1 > t0) is said as what
// happened. Other texts pass through on one line.
std::string describe_simbody_error(const std::string& what);
inline std::string describe_simbody_exception(const std::exception& e) { return describe_simbody_error(e.what()); }

}  // namespace rdyn::engine
