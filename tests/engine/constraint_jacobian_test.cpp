// The constraint Jacobian from the configuration (engine/constraint_jacobian.cpp) against
// Simbody's own calcG (one multiplyByPVA per mobility, an independent route through Simbody's
// constraint velocity errors), and the position errors from q alone against a realized State's
// QErr, on the shipped scenes' kinds of systems: pins and PointOnLine loops
// (four-bar), constraint actuators' slider chains (the bicycle's knee forces), prismatic joints
// (slider-crank, crane), an unfolded gear's coupler row; and the guard that hands a system it does
// not describe back to calcG. The errors and G from the coordinates alone against the same.
#include "engine/constraint_jacobian.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "engine/full_model_impl.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::engine {
namespace {

using SimTK::Matrix;

// max |A − B| over max |B|; NaN when the shapes differ.
double relative_difference(const Matrix& A, const Matrix& B) {
  if (A.nrow() != B.nrow() || A.ncol() != B.ncol()) return NAN;
  double d = 0.0, scale = 0.0;
  for (int i = 0; i < B.nrow(); ++i)
    for (int j = 0; j < B.ncol(); ++j) {
      d = std::max(d, std::abs(A(i, j) - B(i, j)));
      scale = std::max(scale, std::abs(B(i, j)));
    }
  return d / scale;
}

// Both routes at configurations around a whole turn (or stroke) of the independent coordinate,
// each reached by the kinetostatic continuation with a rate, so that the state is a general one.
void expect_as_calc_g(const models::Scene& scene, FullModelOptions o, int expected_rows, double span) {
  const FullModel model(scene, o);
  const auto& m = model.impl();
  ASSERT_TRUE(m.jacobian_plan.has_value()) << scene.source_file;  // else both would be calcG
  EXPECT_EQ(m.jacobian_plan->rows, expected_rows) << scene.source_file;
  FullWorkspace ws(model);
  for (int i = 0; i < 8; ++i) {
    const double q = scene.initial.q + span * i / 8.0;
    calc_kinetostatic(model, ws, q, 1.3, 0.2, Loads::Off);
    const SimTK::State& s = ws.impl().state;
    m.system.realize(s, SimTK::Stage::Position);
    Matrix G, reference;
    calc_constraint_jacobian(m, s, G);
    m.matter.calcG(s, reference);
    ASSERT_EQ(reference.nrow(), expected_rows);
    EXPECT_LE(relative_difference(G, reference), 1e-12) << scene.source_file << " at q = " << q;
    // The route from the coordinates alone (the chord Newton projection's first Jacobian).
    Matrix G_q;
    SimTK::Vector e;
    calc_constraint_errors_and_jacobian(*m.jacobian_plan, s.getQ(), e, G_q);
    EXPECT_LE(relative_difference(G_q, reference), 1e-12) << scene.source_file << " at q = " << q;
    ASSERT_EQ(e.size(), expected_rows);
    for (int i = 0; i < e.size(); ++i) EXPECT_LE(std::abs(e[i]), 1e-11) << scene.source_file << " row " << i;
  }
}

TEST(ConstraintJacobian, FourBarAsCalcG) {
  expect_as_calc_g(models::load_scene("fourbar"), {}, 2, 2 * M_PI);
}

// Two PointOnLine loops; the knee forces' slider chains (Actuator route) as columns.
TEST(ConstraintJacobian, BicycleWithConstraintActuatorsAsCalcG) {
  const auto scene = models::load_scene("bicycle");
  ASSERT_FALSE(scene.outputs.constraint_forces.empty());
  expect_as_calc_g(scene, {}, 4, 2 * M_PI);
}

// The flywheel left as its own body: the gear's CoordinateCoupler adds a row (−r at the crank,
// 1 at the flywheel).
TEST(ConstraintJacobian, UnfoldedGearRowAsCalcG) {
  FullModelOptions o;
  o.fold_geared_bodies = false;
  expect_as_calc_g(models::load_scene("bicycle"), o, 5, 2 * M_PI);
}

TEST(ConstraintJacobian, SlidersAsCalcG) {
  expect_as_calc_g(models::load_scene("slider-crank"), {}, 2, 2 * M_PI);
  const auto crane = models::load_scene("crane-luffing");
  const bool prismatic = crane.find_joint(crane.independent)->type == models::JointType::Prismatic;
  // A prismatic independent coordinate moves 0.3 m of its stroke, a revolute one a turn.
  expect_as_calc_g(crane, {}, 2, prismatic ? 0.3 : 0.5);
}

// The position errors from the coordinates alone against the State's QErr after Simbody's
// Position realization, off the constraint manifold (every coordinate moved by up to 0.05 from
// a closed configuration, so the loops gape by centimetres): equal to 1e-12 of the largest gap.
void expect_errors_as_simbody(const models::Scene& scene, FullModelOptions o) {
  const FullModel model(scene, o);
  const auto& m = model.impl();
  ASSERT_TRUE(m.jacobian_plan.has_value()) << scene.source_file;
  FullWorkspace ws(model);
  calc_kinetostatic(model, ws, scene.initial.q, 0.0, 0.0, Loads::Off);
  SimTK::State s = ws.impl().state;
  const SimTK::Vector closed = s.getQ();
  for (int trial = 0; trial < 6; ++trial) {
    SimTK::Vector q = closed;
    for (int i = 0; i < q.size(); ++i) q[i] += 0.05 * std::sin(1.7 * (i + 1) * (trial + 1));
    s.updQ() = q;
    m.system.realize(s, SimTK::Stage::Position);
    SimTK::Vector e;
    calc_constraint_errors(*m.jacobian_plan, q, e);
    const SimTK::Vector& reference = s.getQErr();
    ASSERT_EQ(e.size(), reference.size());
    double d = 0.0, scale = 0.0;
    for (int i = 0; i < e.size(); ++i) d = std::max(d, std::abs(e[i] - reference[i])), scale = std::max(scale, std::abs(reference[i]));
    EXPECT_GT(scale, 1e-3) << scene.source_file;  // the loops do gape: not zero against zero
    EXPECT_LE(d, 1e-12 * scale) << scene.source_file << " trial " << trial;
    // Errors and G together from q: the same errors, and Simbody's calcG at this configuration
    // (G depends on the configuration, on the manifold or off it).
    SimTK::Vector e2;
    Matrix G, reference_G;
    calc_constraint_errors_and_jacobian(*m.jacobian_plan, q, e2, G);
    m.matter.calcG(s, reference_G);
    ASSERT_EQ(e2.size(), e.size());
    for (int i = 0; i < e.size(); ++i) EXPECT_EQ(e2[i], e[i]) << scene.source_file << " row " << i;
    EXPECT_LE(relative_difference(G, reference_G), 1e-12) << scene.source_file << " trial " << trial;
  }
}

TEST(ConstraintErrors, AsSimbodysOffTheManifold) {
  FullModelOptions unfolded;
  unfolded.fold_geared_bodies = false;
  expect_errors_as_simbody(models::load_scene("fourbar"), {});
  expect_errors_as_simbody(models::load_scene("bicycle"), {});
  expect_errors_as_simbody(models::load_scene("bicycle"), unfolded);  // the gear's row
  expect_errors_as_simbody(models::load_scene("slider-crank"), {});
  expect_errors_as_simbody(models::load_scene("crane-luffing"), {});
}

// Row blocks in constraint order (what calc_mobility reads per constraint, to name redundant
// loops): each equals that constraint's own P from Simbody (calcPositionConstraintMatrixP).
TEST(ConstraintJacobian, RowBlocksAreEachConstraintsP) {
  FullModelOptions o;
  o.fold_geared_bodies = false;  // loops and a gear row
  const FullModel model(models::load_scene("bicycle"), o);
  const auto& m = model.impl();
  ASSERT_TRUE(m.jacobian_plan.has_value());
  FullWorkspace ws(model);
  calc_kinetostatic(model, ws, 2.0, 0.0, 0.0, Loads::Off);
  const SimTK::State& s = ws.impl().state;
  Matrix G;
  calc_constraint_jacobian(m, s, G);
  int first = 0;
  for (size_t k = 0; k < m.constraints.size(); ++k) {
    const Matrix P = m.constraints[k].second.calcPositionConstraintMatrixP(s);
    const int mp = m.jacobian_plan->line_of[k] >= 0 ? 2 : 1;
    ASSERT_EQ(P.nrow(), mp) << m.constraints[k].first;
    EXPECT_LE(relative_difference(G(first, 0, mp, G.ncol()), P), 1e-12) << m.constraints[k].first;
    first += mp;
  }
  EXPECT_EQ(first, G.nrow());
}

// A disabled loop takes its rows out of Simbody's G: the plan no longer describes the system,
// so the guard hands it to calcG (the plan's rows would be 4).
TEST(ConstraintJacobian, DisabledConstraintFallsBackToCalcG) {
  const FullModel model(models::load_scene("bicycle"));
  const auto& m = model.impl();
  ASSERT_TRUE(m.jacobian_plan.has_value());
  FullWorkspace ws(model);
  SimTK::State s = ws.impl().state;
  m.constraints[0].second.disable(s);
  m.system.realize(s, SimTK::Stage::Position);
  Matrix G;
  calc_constraint_jacobian(m, s, G);
  EXPECT_EQ(G.nrow(), 2);
  EXPECT_EQ(G.ncol(), s.getNU());
}

}  // namespace
}  // namespace rdyn::engine
