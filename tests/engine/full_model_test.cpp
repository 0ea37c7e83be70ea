// Building the full model: several constraint forces on one joint (actuator chain against
// Simbody's reactions), branches, assembly from far guesses, refusals of degenerate loads. The
// degrees of freedom by rank: mobility_test.cpp.
#include "engine/full_model.hpp"

#include <gtest/gtest.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/inspect.hpp"
#include "engine/kinetostatic.hpp"
#include "models/scene_yaml.hpp"
#include "engine_refusal.hpp"
#include "test_scenes.hpp"

namespace rdyn::engine {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::has;
using test::refusal;

// The bicycle's right knee with three requests: along the shank (the shipped one), across it
// (+90°) and at +45°.
models::Scene bicycle_with_knee_components() {
  auto scene = models::load_scene("bicycle");
  const auto along = scene.outputs.constraint_forces.at(0);
  auto across = along, diag = along;
  across.name = "knee_across";
  across.direction = {-along.direction.y, along.direction.x};
  diag.name = "knee_diag";
  diag.direction = {(along.direction.x - along.direction.y) / std::sqrt(2.0),
                    (along.direction.y + along.direction.x) / std::sqrt(2.0)};
  scene.outputs.constraint_forces.push_back(across);
  scene.outputs.constraint_forces.push_back(diag);
  return scene;
}

TEST(FullModelConstraintForces, SeveralDirectionsOnOneJointAgreeWithSimbodyReactions) {
  const auto scene = bicycle_with_knee_components();
  FullModelOptions reaction;
  reaction.route = ConstraintForceRoute::Reaction;
  FullModel act(scene), rea(scene, reaction);
  FullWorkspace wa(act), wr(rea);
  double peak = 0;
  for (int deg = 0; deg < 360; deg += 30) {
    const double q = deg * kPi / 180.0;
    const auto fa = calc_kinetostatic(act, wa, q, 6.3, -2.0, Loads::All).constraint_forces;
    const auto fr = calc_kinetostatic(rea, wr, q, 6.3, -2.0, Loads::All).constraint_forces;
    ASSERT_EQ(fa.size(), 3u);
    const double scale = std::max(1.0, std::hypot(fr[0], fr[1]));
    // (i) the slider chain's multipliers against Simbody's mobilizer reaction, per direction.
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(fa[k], fr[k], 1e-9 * scale) << deg << " component " << k;
    // (ii) geometry: projections on d, d⊥ and (d + d⊥)/√2 of one force.
    EXPECT_NEAR(fa[2], (fa[0] + fa[1]) / std::sqrt(2.0), 1e-9 * scale) << deg;
    // (iii) the resultant of along and across is the in-plane magnitude of Simbody's joint
    //       reaction (the Reaction route projects that one vector on two orthonormal d).
    EXPECT_NEAR(std::hypot(fa[0], fa[1]), std::hypot(fr[0], fr[1]), 1e-9 * scale) << deg;
    peak = std::max(peak, std::abs(fa[1]));
  }
  EXPECT_GT(peak, 10.0);  // the across component is not zero: (ii) and (iii) test something
}

TEST(FullModelConstraintForces, RequestOnAPrismaticJointIsAnEngineErrorNotAnAbort) {
  // check_scene refuses it with a line number; a scene built in code must not reach Simbody.
  auto scene = models::load_scene("slider-crank");
  for (const auto& j : scene.joints)
    if (j.type == models::JointType::Prismatic)
      scene.outputs.constraint_forces.push_back({"on_slider", j.name, {1.0, 0.0}});
  const std::string m = [&] {
    try {
      FullModel model(scene);
    } catch (const EngineError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_TRUE(has(m, "constraint force 'on_slider'")) << m;
}


// Explicit branches (a loop's `branch`): the four-bar of models/scenes/fourbar.yaml at crank 30°
// closes at C above or below the line B→D; the rocker angle's sign tells them apart. Closed form:
// C = intersections of |C − B| = 0.28 and |C − D| = 0.20, B = 0.08 (cos 30°, sin 30°), D = (0.3, 0).
std::pair<double, double> fourbar_rocker_angles() {
  const double a = 0.08, b = 0.28, c = 0.20, d = 0.30, th = 30 * kPi / 180;
  const double Bx = a * std::cos(th), By = a * std::sin(th), ex = d - Bx, ey = -By, e = std::hypot(ex, ey);
  const double along = (b * b - c * c + e * e) / (2 * e), h = std::sqrt(b * b - along * along);
  const double px = Bx + along * ex / e, py = By + along * ey / e;
  return {std::atan2(py + h * ex / e, px - h * ey / e - d), std::atan2(py - h * ex / e, px + h * ey / e - d)};
}

models::Scene fourbar_with_branch(const std::string& sign, double coupler_guess, double rocker_guess) {
  return models::load_scene("fourbar", {{"loops.C.branch.joint", "rocker"},
                                        {"loops.C.branch.sign", sign},
                                        {"joints.coupler.guess_deg", std::to_string(coupler_guess)},
                                        {"joints.rocker.guess_deg", std::to_string(rocker_guess)}});
}

double assembled_rocker(const models::Scene& scene) {
  FullModel model(scene);
  FullWorkspace ws(model);
  return calc_kinetostatic(model, ws, scene.initial.q, 0, 0, Loads::Off).joint_q[2];
}

TEST(FullModelBranch, BothBranchesGiveTheClosedFormSolutions) {
  const auto [up, down] = fourbar_rocker_angles();
  ASSERT_GT(up, 0);
  ASSERT_LT(down, 0);
  EXPECT_NEAR(std::remainder(assembled_rocker(fourbar_with_branch("positive", 4.85, 90.27)) - up, 2 * kPi), 0, 1e-10);
  EXPECT_NEAR(std::remainder(assembled_rocker(fourbar_with_branch("negative", -84.5, -110)) - down, 2 * kPi), 0,
              1e-10);
}

TEST(FullModelBranch, GuessesOfTheOtherBranchFailNamingTheLoop) {
  // Without a branch, these guesses silently give the lower assembly...
  auto plain = models::load_scene("fourbar", {{"joints.coupler.guess_deg", "-84.5"},
                                              {"joints.rocker.guess_deg", "-110"}});
  EXPECT_LT(std::remainder(assembled_rocker(plain), 2 * kPi), 0);
  // ...with the upper branch named, they are refused.
  const std::string m = refusal(fourbar_with_branch("positive", -84.5, -110));
  EXPECT_TRUE(has(m, "loop 'C' assembled on the other branch")) << m;
  EXPECT_TRUE(has(m, "joint 'rocker' is at -109.9")) << m;
  EXPECT_TRUE(has(m, "loops.C.branch")) << m;
  EXPECT_TRUE(has(m, "fourbar.yaml")) << m;
}

// A parallelogram chain started near its flat configuration with the shipped guesses (90°, −90°):
// Newton's steps from them left a 2 m gap at 0.01°, folded the loop into the antiparallelogram at
// 0.1°, and put crank1 8224 turns away at 0.5°. Assembly now walks from the configuration the
// guesses describe: the parallelogram (crank1 turned as crank0, the coupler level), every angle
// within half a turn of its guess. Across the flat configuration from the guesses (−0.1°) the
// walk does not go (the branch would be an accident): refused, naming the guesses.
TEST(FullModelAssembly, FarGuessesNearAFlatConfigurationWalkToTheStart) {
  // Starts across a flat configuration from the guesses' 90° (−30°, 180.1°, −179.99°, 270°): the
  // walk continues through it along the guesses' branch (follow_branch); the direct assembly
  // landed folded there (crank1 at 180°) with only a far-from-guess warning.
  for (double deg : {0.5, 0.1, 0.01, 0.003, 179.9, 45.0, 270.0, -30.0, 180.1, -179.99, -0.1, -0.01, 359.99}) {
    const auto scene =
        models::load_scene(RDYN_SCENES "/chains/chain-1.yaml", {{"initial.q_deg", fmt::format("{}", deg)}});
    const Inspection a = calc_assembly(FullModel(scene));
    auto angle = [&](const std::string& body) -> double {
      for (const auto& b : a.bodies)
        if (b.name == body) return b.angle_rad;
      ADD_FAILURE() << body;
      return std::nan("");
    };
    EXPECT_NEAR(std::remainder(angle("crank1") - angle("crank0"), 2 * kPi), 0, 1e-9) << deg << "°";
    EXPECT_NEAR(std::remainder(angle("coupler0"), 2 * kPi), 0, 1e-9) << deg << "°";
    for (const auto& j : a.joints)  // the independent coordinate is the initial q as given
      if (j.name != "crank0") {
        EXPECT_LE(std::abs(j.q - j.guess), kPi + 1e-12) << j.name << " at " << deg << "°";
      }
  }
  // Starts on a flat configuration itself, by any label of it: the singular-start refusal.
  for (const char* deg : {"0", "360", "-180", "540"}) {
    const auto flat = models::load_scene(RDYN_SCENES "/chains/chain-1.yaml", {{"initial.q_deg", deg}});
    try {
      FullModel model(flat);
      FullWorkspace ws(model);
      ADD_FAILURE() << deg << "° accepted";
    } catch (const models::SceneError& e) {
      EXPECT_EQ(e.field(), "initial") << deg;
      EXPECT_TRUE(has(e.what(), "starts at a singular configuration")) << e.what();
    }
  }
}

// A five-bar whose fast crank is geared 6:1 to the independent slow crank
// (tests/validate/scenes/fivebar-6to1.yaml): the gear holds absolute angles, fast = 6·slow + c,
// so a start n turns on puts the fast crank 6n turns on. The assembly's wrap of every angle to
// within half a turn of its guess turned the fast crank back too: at 430.2° it left the coupler
// 37.7 rad off, and the first projection there (validate's cycle run) failed with "cannot reach".
models::Scene fivebar_6to1(double q_deg) {
  return models::load_scene(RDYN_TEST_SCENES "/fivebar-6to1.yaml", {{"initial.q_deg", fmt::format("{}", q_deg)}});
}

// The joint angles at a start, projected there by calc_kinetostatic [rad].
std::vector<double> fivebar_6to1_joints(double q_deg) {
  const auto scene = fivebar_6to1(q_deg);
  FullModel model(scene);
  FullWorkspace ws(model);
  return calc_kinetostatic(model, ws, scene.initial.q, 0, 0, Loads::Off).joint_q;
}

// The same configuration, every joint equal modulo a turn.
void expect_same_configuration(const std::vector<double>& a, const std::vector<double>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t j = 0; j < a.size(); ++j)
    EXPECT_NEAR(std::remainder(a[j] - b[j], 2 * kPi), 0, 1e-9) << what << " joint " << j;
}

TEST(FullModelAssembly, GearedStartATurnOnProjectsToTheSameConfiguration) {
  const auto scene = fivebar_6to1(0);
  const auto& joints = scene.joints;
  auto index = [&](const std::string& name) { return static_cast<size_t>(scene.joint_index(name)); };
  const double c = joints[index("fast")].guess - 6.0 * joints[index("slow")].guess;
  const auto base = fivebar_6to1_joints(70.2), turned = fivebar_6to1_joints(430.2);
  expect_same_configuration(base, turned, "430.2° against 70.2°");
  for (const auto* q : {&base, &turned})  // the coupler's condition, not modulo a turn
    EXPECT_NEAR((*q)[index("fast")], 6.0 * (*q)[index("slow")] + c, 1e-9 * (1 + std::abs((*q)[index("fast")])));
  EXPECT_NEAR(turned[index("slow")], 430.2 * kPi / 180, 1e-12);
}

// A gearless mechanism started many turns away (inside the scene limit of 5.7e7°) walks only the
// last part of a turn: 1e6° was refused as "across a singular configuration" after no move at all.
TEST(FullModelAssembly, AStartManyTurnsAwayIsTheSameConfigurationAsItsRemainder) {
  auto joints_at = [](double q_deg) {
    auto scene = models::load_scene("fourbar");
    scene.initial.q = q_deg * kPi / 180;
    FullModel model(scene);
    FullWorkspace ws(model);
    return calc_kinetostatic(model, ws, scene.initial.q, 0, 0, Loads::Off).joint_q;
  };
  expect_same_configuration(joints_at(1e6), joints_at(280), "1e6° against 280°");
  expect_same_configuration(joints_at(-1e6), joints_at(80), "-1e6° against 80°");
  expect_same_configuration(joints_at(500000 + 0.5), joints_at(320.5), "500000.5° against 320.5°");
  EXPECT_NEAR(joints_at(1e6)[0], 1e6 * kPi / 180, 1e-12 * 1e6);  // the coordinate as given
}

// The five-bar's closed form on the scene's branch (P left of T_slow → T_fast): slow θ, fast
// φ = 6θ + c, T_slow = 0.07 (cos θ, sin θ), T_fast = B + 0.05 (cos φ, sin φ), P where the arms
// (0.22 m from T_slow, 0.20 m from T_fast) meet; arm1 = ∠(P − T_slow) − θ, arm2 = ∠(P − T_fast) − φ.
// Joint angles in scene order: slow, arm1, fast, arm2 [rad].
std::vector<double> fivebar_6to1_closed_form(double theta) {
  const double phi = 6 * theta + (45 - 6 * 90) * kPi / 180;
  const double x1 = 0.07 * std::cos(theta), y1 = 0.07 * std::sin(theta);
  const double x2 = 0.25 + 0.05 * std::cos(phi), y2 = 0.05 * std::sin(phi);
  const double d = std::hypot(x2 - x1, y2 - y1), ex = (x2 - x1) / d, ey = (y2 - y1) / d;
  const double a = (0.22 * 0.22 - 0.20 * 0.20 + d * d) / (2 * d), h = std::sqrt(0.22 * 0.22 - a * a);
  const double px = x1 + a * ex - h * ey, py = y1 + a * ey + h * ex;
  return {theta, std::atan2(py - y1, px - x1) - theta, phi, std::atan2(py - y2, px - x2) - phi};
}

// Starts every 7.3° from −400° to 800° (continuation walks and direct assemblies, near the guesses
// and far), in four interleaved parts (each ~15 s: the walks from the guesses take up to 360 moves):
// each assembles and projects at its q to the closed form's configuration, every joint modulo a
// turn, and keeps the gear's relation exactly. The scene's `branch` (arm2's angle positive) is
// left out: arm2 turns against the fast crank, which turns six times a slow turn, so that sign is
// not the branch and refuses half the starts (0°, 1.5°, 45.3°, … also before this fix).
class GearedStarts : public ::testing::TestWithParam<int> {};

TEST_P(GearedStarts, AllAssembleAndProject) {
  std::string yaml = models::read_scene_text(RDYN_TEST_SCENES "/fivebar-6to1.yaml");
  const std::string branch = ", branch: {joint: arm2, sign: positive}";
  ASSERT_NE(yaml.find(branch), std::string::npos);
  yaml.erase(yaml.find(branch), branch.size());
  for (int k = 0; -400.0 + 7.3 * k <= 800.0; ++k) {
    const double deg = -400.0 + 7.3 * k;
    if (k % 4 != GetParam()) continue;  // another part's
    const auto scene = models::parse_scene(yaml, "fivebar-6to1.yaml", {{"initial.q_deg", fmt::format("{}", deg)}});
    try {
      FullModel model(scene);
      FullWorkspace ws(model);
      const auto q = calc_kinetostatic(model, ws, scene.initial.q, 0, 0, Loads::Off).joint_q;
      expect_same_configuration(q, fivebar_6to1_closed_form(scene.initial.q), fmt::format("{}°", deg));
      EXPECT_NEAR(q[2], 6 * q[0] + (45 - 6 * 90) * kPi / 180, 1e-9 * (1 + std::abs(q[2]))) << deg << "°";
    } catch (const std::exception& e) {
      ADD_FAILURE() << deg << "°: " << e.what();
    }
  }
}

INSTANTIATE_TEST_SUITE_P(FullModelAssembly, GearedStarts, ::testing::Range(0, 4));

// A point force whose points coincide where the mechanism assembles has no direction: refused
// as bad input, naming the file, the line of its point_b and the field.
TEST(FullModelPointForce, CoincidentPointsAtAssemblyAreASceneErrorWithItsLine) {
  const std::string path = ::testing::TempDir() + "coincident_point_force.yaml";
  const std::string load = "  - {type: point_force, name: m, body_a: ground, point_a: [0.1, 0], body_b: crank, "
                           "point_b: B, force_N: 5}\n";
  std::string yaml = test::pulled_crank_yaml(5);
  yaml.replace(yaml.find("  - {type: point_force"), yaml.find("gravity:") - yaml.find("  - {type: point_force"), load);
  yaml.replace(yaml.find("q_deg: 150"), 10, "q_deg: 0");  // B = (0.1, 0) = point_a
  {
    std::ofstream out(path);
    out << yaml;
  }
  const auto scene = models::load_scene(path);
  FullModel model(scene);
  try {
    FullWorkspace ws(model);
    FAIL() << "assembled";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "loads.m.point_b");
    const auto at = yaml.find(load);
    EXPECT_EQ(e.line(), 1 + std::count(yaml.begin(), yaml.begin() + static_cast<long>(at), '\n')) << e.what();
    EXPECT_NE(e.message().find("no direction"), std::string::npos) << e.what();
  }
  // A turn away they are 0.2 m apart: accepted.
  yaml.replace(yaml.find("q_deg: 0"), 8, "q_deg: 180");
  const FullModel ok(models::parse_scene(yaml, "ok.yaml"));
  EXPECT_NO_THROW(FullWorkspace{ok});
}

// Simbody's exception texts reach users as words: no source file and line, no boilerplate, one
// line; the condition it checked as a hint; the integrator's zero-length event interval
// (Required condition 't1 > t0', issue #23) said as what happened.
TEST(SimbodyMessages, ExceptionTextsAreSaidInWords) {
  // The texts as Simbody 3.7 formats them (SimTKcommon/internal/Exception.h: ErrorCheck,
  // APIArgcheckFailed).
  const std::string z = describe_simbody_error(
      "SimTK Exception thrown at Integrator.cpp:412:\n  Error detected by Simbody method Integrator::stepTo(): Event "
      "interval [2, 2] has no length.\n  (Required condition 't1 > t0' was not met.)\n");
  EXPECT_EQ(z.rfind("the integrator's step shrank to zero length while it located a load switch", 0), 0u) << z;
  const std::string bad = describe_simbody_error(
      "SimTK Exception thrown at State.cpp:7:\n  Bad call to Simbody API method State::setN(): n=-1\nnot positive\n"
      "  (Required condition 'n > 0' was not met.)");
  EXPECT_EQ(bad, "Bad call to Simbody API method State::setN(): n=-1 not positive [Simbody's condition: n > 0]");
  for (const std::string& m : {z, bad}) {
    EXPECT_EQ(m.find("SimTK Exception thrown"), std::string::npos) << m;
    EXPECT_EQ(m.find(".cpp"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_EQ(describe_simbody_exception(std::runtime_error("plain\ntext")), "plain text");
}

// A spring whose ends coincide where the mechanism assembles has no line of action: refused as
// the point force above (issue #22 item 6), naming its point_b's line.
TEST(FullModelSpring, CoincidentEndsAtAssemblyAreASceneErrorWithItsLine) {
  const std::string load = "  - {type: spring, name: k, body_a: ground, point_a: [0.1, 0], body_b: crank, "
                           "point_b: B, stiffness_N_per_m: 100, rest_length_m: 0.05}\n";
  std::string yaml = test::pulled_crank_yaml(5);
  yaml.replace(yaml.find("  - {type: point_force"), yaml.find("gravity:") - yaml.find("  - {type: point_force"), load);
  yaml.replace(yaml.find("q_deg: 150"), 10, "q_deg: 0");  // B = (0.1, 0) = point_a
  const std::string path = ::testing::TempDir() + "coincident_spring.yaml";
  {
    std::ofstream out(path);
    out << yaml;
  }
  const FullModel model(models::load_scene(path));
  try {
    FullWorkspace ws(model);
    FAIL() << "assembled";
  } catch (const models::SceneError& e) {
    EXPECT_EQ(e.field(), "loads.k.point_b");
    const auto at = yaml.find(load);
    EXPECT_EQ(e.line(), 1 + std::count(yaml.begin(), yaml.begin() + static_cast<long>(at), '\n')) << e.what();
    EXPECT_TRUE(has(e.message(), "spring 'k'")) << e.what();
    EXPECT_TRUE(has(e.message(), "no direction")) << e.what();
  }
  yaml.replace(yaml.find("q_deg: 0"), 8, "q_deg: 180");
  const FullModel ok(models::parse_scene(yaml, "ok.yaml"));
  EXPECT_NO_THROW(FullWorkspace{ok});
}

}  // namespace
}  // namespace rdyn::engine
