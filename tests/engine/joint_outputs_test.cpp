// Every joint's motion and reaction and the shaking load of the full model
// (engine/joint_outputs.cpp) against routes that do not use Simbody's reactions: Newton–Euler
// of every body of the four-bar with centre-of-mass accelerations from closed-form kinematics
// of the output joint motions, and the slider-crank's pin forces.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "engine/forward_dynamics.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::engine {
namespace {

struct FullRun {
  TimeSeries ts;
  std::map<std::string, int> col;
  double at(const std::string& name, size_t i) const { return ts.columns[col.at(name)][i]; }
};

FullRun simulate(const std::string& scene_name, std::vector<models::Override> sets,
             ConstraintForceRoute route = ConstraintForceRoute::Actuator) {
  sets.push_back({"outputs.joints", "all"});
  sets.push_back({"outputs.reactions", "all"});
  sets.push_back({"outputs.shaking", "true"});
  const auto scene = models::load_scene(scene_name, sets);
  FullModelOptions mo;
  mo.route = route;
  FullModel model(scene, mo);
  ForwardOptions opt;
  opt.duration_s = 0.5;
  opt.output_interval_s = 0.01;
  opt.tolerance = 1e-10;
  FullRun r{simulate_full(model, opt), {}};
  for (size_t c = 0; c < r.ts.column_names.size(); ++c) r.col[r.ts.column_names[c]] = static_cast<int>(c);
  return r;
}

// Acceleration of the point at distance L along a body at angle θ (rate ω, acceleration α) from
// a point with acceleration a0: a0 + α k × e L − ω² e L.
void add_rotating(double L, double th, double w, double al, double& ax, double& ay) {
  ax += L * (-std::sin(th) * al - std::cos(th) * w * w);
  ay += L * (std::cos(th) * al - std::sin(th) * w * w);
}

TEST(JointOutputs, FourBarReactionsSatisfyNewtonEulerForEveryBody) {
  // models/scenes/fourbar.yaml: crank 0.08 (com 0.04, 0.5 kg), coupler 0.28 (com 0.14, 1.2 kg),
  // rocker 0.20 (com 0.10, 0.9 kg), gravity −9.81 y.
  const FullRun r = simulate("fourbar", {});
  const double g = -9.81, m1 = 0.5, m2 = 1.2, m3 = 0.9;
  double worst = 0, scale = 0;
  for (size_t i = 0; i < r.ts.t.size(); ++i) {
    const double t1 = r.at("q_crank", i), w1 = r.at("qdot_crank", i), a1 = r.at("qddot_crank", i);
    const double t2 = t1 + r.at("q_coupler", i), w2 = w1 + r.at("qdot_coupler", i),
                 a2 = a1 + r.at("qddot_coupler", i);
    const double t3 = r.at("q_rocker", i), w3 = r.at("qdot_rocker", i), a3 = r.at("qddot_rocker", i);
    EXPECT_EQ(t1, r.ts.q[i]);  // the independent joint's columns are q itself
    double c1x = 0, c1y = 0, c2x = 0, c2y = 0, c3x = 0, c3y = 0;
    add_rotating(0.04, t1, w1, a1, c1x, c1y);
    add_rotating(0.08, t1, w1, a1, c2x, c2y);  // pin B
    add_rotating(0.14, t2, w2, a2, c2x, c2y);
    add_rotating(0.10, t3, w3, a3, c3x, c3y);
    const double Rc[2] = {r.at("R_crank_x", i), r.at("R_crank_y", i)};      // ground on crank
    const double Rb[2] = {r.at("R_coupler_x", i), r.at("R_coupler_y", i)};  // crank on coupler
    const double Rr[2] = {r.at("R_rocker_x", i), r.at("R_rocker_y", i)};    // ground on rocker
    const double Rl[2] = {r.at("R_C_x", i), r.at("R_C_y", i)};              // coupler on rocker
    const double res[] = {Rc[0] - Rb[0] - m1 * c1x,          Rc[1] - Rb[1] + m1 * g - m1 * c1y,
                          Rb[0] - Rl[0] - m2 * c2x,          Rb[1] - Rl[1] + m2 * g - m2 * c2y,
                          Rr[0] + Rl[0] - m3 * c3x,          Rr[1] + Rl[1] + m3 * g - m3 * c3y,
                          // shaking = load on the ground = −(ground's forces on crank and rocker)
                          r.at("shaking_x", i) + Rc[0] + Rr[0], r.at("shaking_y", i) + Rc[1] + Rr[1]};
    for (double x : res) worst = std::max(worst, std::abs(x));
    for (double x : {Rc[0], Rc[1], Rl[0], Rl[1]}) scale = std::max(scale, std::abs(x));
  }
  EXPECT_GT(scale, 10.0);  // forces of tens of newtons
  EXPECT_LT(worst, 1e-6 * scale);
}

TEST(JointOutputs, FourBarShakingMomentIsTheGroundReactionsMoment) {
  // The ground holds the mechanism at A (0, 0) and D (0.3, 0) and takes the reaction of the
  // crank's viscous bearing (c = 1e-3 N·m·s, torque −c ω on the crank): the mechanism's moment on
  // the ground about O is −(r_A × R_crank + r_D × R_rocker + (−c ω)).
  const FullRun r = simulate("fourbar", {});
  double worst = 0, scale = 0;
  for (size_t i = 0; i < r.ts.t.size(); ++i) {
    const double expected = -(0.3 * r.at("R_rocker_y", i) - 1e-3 * r.at("qdot_crank", i));
    worst = std::max(worst, std::abs(r.at("shaking_M", i) - expected));
    scale = std::max(scale, std::abs(expected));
  }
  EXPECT_GT(scale, 1.0);
  EXPECT_LT(worst, 1e-6 * scale);
}

TEST(JointOutputs, ReactionsDoNotDependOnTheConstraintForceRoute) {
  const FullRun a = simulate("fourbar", {}, ConstraintForceRoute::Actuator);
  const FullRun b = simulate("fourbar", {}, ConstraintForceRoute::Reaction);
  ASSERT_EQ(a.ts.column_names, b.ts.column_names);
  for (size_t c = 0; c < a.ts.columns.size(); ++c)
    for (size_t i = 0; i < a.ts.t.size(); ++i)
      EXPECT_NEAR(a.ts.columns[c][i], b.ts.columns[c][i], 1e-6 * (1 + std::abs(b.ts.columns[c][i])))
          << a.ts.column_names[c] << " at t = " << a.ts.t[i];
  // F_rocker_axial (actuator multiplier) is R_rocker projected on the rocker's axis.
  for (size_t i = 0; i < a.ts.t.size(); ++i) {
    const double th = a.at("q_rocker", i);
    EXPECT_NEAR(a.ts.forces[0][i], a.at("R_rocker_x", i) * std::cos(th) + a.at("R_rocker_y", i) * std::sin(th),
                1e-6 * (1 + std::abs(a.ts.forces[0][i])));
  }
}

TEST(JointOutputs, SliderCrankPinForcesInClosedForm) {
  // Horizontal slider-crank (no gravity): the slider (1.5 kg) moves along x, pushed by the rod at
  // the wrist pin and by the −40 N piston load acting in its joint; the rod (0.6 kg, com 0.08 m
  // from B, 0.20 m long) is a two-force member only when massless, so check Newton–Euler of the
  // slider, the rod's moment balance about its com, and the joint's normal force.
  const FullRun r = simulate("slider-crank", {});
  const double ms = 1.5, mr = 0.6, Ir = 2.0e-3;
  for (size_t i = 0; i < r.ts.t.size(); ++i) {
    const double as = r.at("qddot_slider", i);
    // Slider: R_slider (ground, includes the piston load along the axis) + pin = m a, a along x.
    EXPECT_NEAR(r.at("R_slider_x", i) + r.at("R_wrist_pin_x", i), ms * as, 1e-6 * (1 + ms * std::abs(as)));
    EXPECT_NEAR(r.at("R_slider_y", i) + r.at("R_wrist_pin_y", i), 0.0, 1e-6);
    EXPECT_NEAR(r.at("R_slider_x", i), -40.0, 1e-9);  // the piston load is the joint's only axial force
    EXPECT_NEAR(r.at("R_slider_normal", i), r.at("R_slider_y", i), 1e-12);  // axis +x: normal +y
    EXPECT_NEAR(r.at("R_slider_M", i), 0.0, 1e-9);  // pin and centre of mass at the child point
    // Rod, moments about its centre of mass: pin B force (crank on rod) at −0.08 e, pin C force
    // (−R_wrist_pin) at +0.12 e, e = rod direction; I α = Σ r × F.
    const double th = r.at("q_crank", i) + r.at("q_rod", i), ex = std::cos(th), ey = std::sin(th);
    const double al = r.at("qddot_crank", i) + r.at("qddot_rod", i);
    const double Bx = r.at("R_rod_x", i), By = r.at("R_rod_y", i);
    const double Cx = -r.at("R_wrist_pin_x", i), Cy = -r.at("R_wrist_pin_y", i);
    const double M = -0.08 * (ex * By - ey * Bx) + 0.12 * (ex * Cy - ey * Cx);
    EXPECT_NEAR(M, Ir * al, 1e-6 * (1 + std::abs(Ir * al)));
    (void)mr;
  }
}


TEST(JointOutputs, ConstraintForceOnTheIndependentJointMatchesItsReaction) {
  // A request on the crank (the independent joint) along the crank: the actuator route's slider
  // multiplier equals Simbody's reaction projected on the crank's direction.
  const std::vector<models::Override> sets{{"outputs.constraint_forces.rocker_axial.joint", "crank"},
                                           {"outputs.constraint_forces.rocker_axial.direction", "B"}};
  const FullRun a = simulate("fourbar", sets, ConstraintForceRoute::Actuator);
  double peak = 0;
  for (size_t i = 0; i < a.ts.t.size(); ++i) {
    const double th = a.at("q_crank", i), f = a.ts.forces[0][i];
    peak = std::max(peak, std::abs(f));
    EXPECT_NEAR(f, a.at("R_crank_x", i) * std::cos(th) + a.at("R_crank_y", i) * std::sin(th), 1e-6 * (1 + std::abs(f)));
  }
  EXPECT_GT(peak, 10.0);
}

}  // namespace
}  // namespace rdyn::engine
