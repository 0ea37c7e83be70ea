// The every-joint runs the drawings are made from: row 0 is the full model's assembly (Simbody's
// own joint coordinates, engine::calc_assembly), and every row's coordinates close the loops
// when models::calc_pose places the bodies (the loop points meet).
#include "validate/analysis/mechanism_run.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "engine/full_model.hpp"
#include "engine/inspect.hpp"
#include "models/pose.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

double max_loop_gap(const models::Scene& s, const models::TimeSeries& ts) {
  double gap = 0;
  for (size_t r = 0; r < ts.t.size(); ++r) {
    const auto pose = models::calc_pose(s, joint_coordinates(s, ts, r));
    for (const auto& l : s.loops) {
      const auto a = models::calc_ground_point(s, pose, l.body_a, l.point_a);
      const auto b = models::calc_ground_point(s, pose, l.body_b, l.point_b);
      gap = std::max(gap, std::hypot(a.x - b.x, a.y - b.y));
    }
  }
  return gap;
}

TEST(MechanismRun, EveryJointIsOutput) {
  const auto s = models::load_scene("fourbar", {});
  const auto e = with_every_joint_output(s);
  ASSERT_EQ(e.outputs.joints.size(), s.joints.size());
  for (size_t j = 0; j < s.joints.size(); ++j) EXPECT_EQ(e.outputs.joints[j], s.joints[j].name);
}

TEST(MechanismRun, FullRunStartsAtTheAssemblyAndKeepsItsLoopsClosed) {
  const auto s = models::load_scene(std::string(RDYN_SCENES) + "/chains/chain-3.yaml", {});
  const auto ts = simulate_every_joint(s, "full", 0.5, 0.01);
  const auto in = engine::calc_assembly(engine::FullModel(s));
  const auto q0 = joint_coordinates(s, ts, 0);
  ASSERT_EQ(q0.size(), in.joints.size());
  for (size_t j = 0; j < q0.size(); ++j) EXPECT_NEAR(q0[j], in.joints[j].q, 1e-9) << in.joints[j].name;
  EXPECT_LT(max_loop_gap(s, ts), 1e-8);  // Simbody holds the constraints to its tolerance, 1e-9
}

TEST(MechanismRun, ReducedRunKeepsTheLoopsClosedToItsTableAccuracy) {
  const auto s = models::load_scene("fourbar", {});
  const auto ts = simulate_every_joint(s, "reduced", 0.5, 0.01);
  // Joint coordinates from the table's cubic columns at a 10° grid: the loops close to the
  // interpolation error, a small fraction of the 0.3 m mechanism, not exactly.
  EXPECT_LT(max_loop_gap(s, ts), 1e-3);
  EXPECT_THROW(joint_coordinates(s, ts, ts.t.size()), std::invalid_argument);
}

}  // namespace
}  // namespace rdyn::validate
