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
  std::optional<std::pair<double, double>> ratio_and_slope(double q, int joint) override;
  std::optional<double> joint_coordinate(double q, int joint) override;
  long calls() const { return calls_; }

 private:
  // Walks the configuration to q in steps of at most max_jump so that each Newton
  // projection starts close (continuation keeps the assembled branch).
  // With `from_anchor`, a target within one jump of the last grid point is reached by
  // calc_kinetostatic_sample's predictor from there (no intermediate moves).
  void approach(double q, double max_jump, bool from_anchor);
  // Runs `call` at q after approaching it; when a projection fails (close to a singular
  // configuration Newton can stall from 5° away), goes back to the last good configuration
  // and approaches again in finer steps (1°, then 0.1°).
  template <typename F>
  auto at(double q, F&& call, bool from_anchor = false);
  // The kinetostatic calls (i), (ii), the static call and the velocity ratios made one by one
  // (the Reaction constraint-force route, and the reference route of the tests).
  reduced::GridSample sample_here(double q, bool with_conservative);
  // One projection and one realization (calc_kinetostatic_sample), the static call when asked.
  reduced::GridSample sample_fast(double q, bool with_conservative);
  std::optional<reduced::DirectPoint> direct_here(double q);
  const FullModel& model_;
  FullWorkspace ws_;
  bool wrap_turns_;
  double max_jump_;  // longest continuation move: 10° (revolute) or 1/20 of the mechanism's size (prismatic)
  double q_now_;
  long calls_ = 0;
  std::optional<double> anchor_;  // the last grid point sampled by sample_fast
  double extrapolation_ = 0.0;   // set by approach: how far the predictor may reach for this call
};

}  // namespace rdyn::engine
