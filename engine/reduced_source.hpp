// The full model as a reduced::KinetostaticSource: what reduced/ extraction calls.
#pragma once

#include "engine/full_model.hpp"
#include "reduced/kinetostatic_source.hpp"

namespace rdyn::engine {

class FullKinetostaticSource : public reduced::KinetostaticSource {
 public:
  // wrap_turns: a revolute independent coordinate is approached by its periodic image nearest
  // the current configuration (periodic tables); false for a range table, whose points lie on
  // one side of the dead points and must be walked to directly (a range may exceed 180°).
  explicit FullKinetostaticSource(const FullModel& model, bool wrap_turns = true);
  int num_constraint_forces() const override;
  int num_joints() const override;
  reduced::ForcePoint inertial(double q, double qdot, double qddot) override;
  reduced::ConservativePoint conservative(double q) override;
  reduced::RatioPoint ratios(double q) override;
  std::optional<reduced::ForcePoint> harmonic_sweep(const double c[5], double t) override;
  std::optional<reduced::DirectPoint> direct(double q) override;
  reduced::GridSample sample(double q, bool with_conservative) override;
  double ratio(double q, int joint) override;
  std::optional<double> joint_coordinate(double q, int joint) override;
  long calls() const { return calls_; }

 private:
  // Walks the configuration to q in steps of at most max_jump so that each Newton
  // projection starts close (continuation keeps the assembled branch).
  void approach(double q, double max_jump);
  // Runs `call` at q after approaching it; when a projection fails (close to a singular
  // configuration Newton can stall from 5° away), goes back to the last good configuration
  // and approaches again in finer steps (1°, then 0.1°).
  template <typename F>
  auto at(double q, F&& call);
  reduced::GridSample sample_here(double q, bool with_conservative);
  std::optional<reduced::DirectPoint> direct_here(double q);
  const FullModel& model_;
  FullWorkspace ws_;
  bool wrap_turns_;
  double max_jump_;  // longest continuation move: 10° (revolute) or 1/20 of the mechanism's size (prismatic)
  double q_now_;
  long calls_ = 0;
};

}  // namespace rdyn::engine
