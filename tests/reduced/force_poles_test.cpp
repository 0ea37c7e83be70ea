// check_force_poles (reduced/force_poles.cpp): a row within the pole band of a requested force's
// pole is refused with the force named as the scene names it — a reaction's internal line by its
// joint and the columns the user sees, not 'R_<joint>_gx'.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "models/scene.hpp"
#include "reduced/reduced_model.hpp"

namespace rdyn::reduced {
namespace {

std::string refusal(const ReducedModel& m, double q) {
  try {
    check_force_poles(m, q, 0.25);
  } catch (const models::NumericalError& e) {
    return e.what();
  }
  return "";
}

TEST(ForcePoles, ARowNearAPoleIsRefusedNamingTheForceAsTheSceneDoes) {
  ReducedModel m;
  m.revolute = true;
  m.force_names = {"rod_axial", "R_crank_gx"};
  m.force_poles = {{M_PI / 2}, {M_PI}};
  m.pole_band = 0.05;
  EXPECT_EQ(refusal(m, 1.0), "");  // 0.57 rad from the nearest pole
  const std::string rod = refusal(m, M_PI / 2 + 0.01);
  EXPECT_NE(rod.find("cannot give constraint force 'rod_axial' at t = 0.25 s, q = 90.573°"), std::string::npos) << rod;
  EXPECT_NE(rod.find("leave 'rod_axial' out of the scene's outputs"), std::string::npos) << rod;
  const std::string reaction = refusal(m, M_PI - 2 * M_PI + 0.02);  // a turn away: the same configuration
  EXPECT_NE(reaction.find("cannot give the reaction of joint 'crank' (R_crank_x, R_crank_y)"), std::string::npos)
      << reaction;
  EXPECT_NE(reaction.find("leave joint 'crank' out of outputs.reactions"), std::string::npos) << reaction;
  EXPECT_EQ(reaction.find("R_crank_gx"), std::string::npos) << reaction;
}

}  // namespace
}  // namespace rdyn::reduced
