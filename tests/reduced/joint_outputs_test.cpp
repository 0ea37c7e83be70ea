// Joint motions, reactions and shaking of the reduced model (reduced/joint_outputs.cpp): the
// column names and reaction lines it asks for, and end to end through the rdyn binary against
// the full model (Simbody's mobilizer reactions and loop multipliers, engine/joint_outputs.cpp):
// the two routes share nothing but the scene.
#include "reduced/joint_outputs.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "analytic_source.hpp"
#include "models/scene_yaml.hpp"
#include "reduced/extract.hpp"
#include "reduced/simulate_reduced.hpp"

namespace rdyn::reduced {
namespace {

namespace fs = std::filesystem;

TEST(JointOutputNames, ColumnsInOrderAndReactionLinesForLoops) {
  const auto s = models::load_scene("slider-crank", {{"outputs.joints", "all"}, {"outputs.shaking", "true"}});
  const auto n = joint_output_names(s);
  ASSERT_EQ(n.size(), 3u * 3 + 3);
  EXPECT_EQ(n[0], "q_crank");
  EXPECT_EQ(n[5], "qddot_rod");
  EXPECT_EQ(n[9], "shaking_x");
  // The wrist pin's force by Newton–Euler of the rod (the slider hangs from a prismatic joint):
  // reaction lines on the rod's joint, two components each.
  // The slider's own reaction by Newton–Euler of the slider, which needs the wrist pin's force.
  auto r = models::load_scene("slider-crank", {{"outputs.reactions", "all"}});
  const auto aug = with_reaction_requests(r);
  std::vector<std::string> lines;
  for (const auto& c : aug.outputs.constraint_forces) lines.push_back(c.name);
  EXPECT_EQ(lines, (std::vector<std::string>{"rod_axial", "R_crank_gx", "R_crank_gy", "R_rod_gx", "R_rod_gy"}));
  // A spring on the slider would enter its balance: refused, naming the joint and the spring.
  r.springs.push_back({"return", "slider", {0, 0}, "ground", {0.3, 0}, 100.0, 0.05});
  try {
    with_reaction_requests(r);
    ADD_FAILURE() << "accepted";
  } catch (const TableError& e) {
    EXPECT_NE(std::string(e.what()).find("prismatic joint 'slider': its child 'slider' carries spring 'return'"),
              std::string::npos)
        << e.what();
  }
}

// A point force on a body whose Newton–Euler balance gives a reaction would enter that balance:
// refused like a spring (the full model gives those reactions).
TEST(JointOutputNames, PointForceOnABalancedBodyIsRefusedLikeASpring) {
  auto r = models::load_scene("slider-crank", {{"outputs.reactions", "all"}});
  models::PointForce pf;
  pf.name = "pull";
  pf.body_a = "ground";
  pf.point_a = {0.3, 0.1};
  pf.body_b = "slider";
  pf.value = 10;
  r.point_forces.push_back(pf);
  try {
    with_reaction_requests(r);
    ADD_FAILURE() << "accepted";
  } catch (const TableError& e) {
    EXPECT_NE(std::string(e.what()).find("its child 'slider' carries point force 'pull'"), std::string::npos)
        << e.what();
  }
  // On the crank (a revolute joint's child: its reaction comes from its own lines) it is accepted.
  r.point_forces[0].body_b = "crank";
  r.outputs.reactions = {"crank"};
  EXPECT_NO_THROW(with_reaction_requests(r));
}

// joint_output_columns names what the joint outputs read beside the reduced model's columns: on a
// table of only those (select_columns) the joint motions are those of the whole table bit for bit,
// and without any one of them make_joint_output_model refuses the table.
TEST(JointOutputNames, TheColumnsTheyReadGiveTheSameOutputs) {
  auto scene = test::analytic_scene();
  scene.joint_torques.push_back({"drive", "lever", 0.2, std::nullopt, std::nullopt});
  scene.outputs.joints = {"crank", "lever"};
  // The analytic source with its joints' coordinates (crank q, lever sin q) at each grid sample.
  struct WithPositions : test::AnalyticSource {
    RatioPoint ratios(double q) override {
      auto r = AnalyticSource::ratios(q);
      r.joint_q = {q, std::sin(q)};
      return r;
    }
  } src;
  ExtractOptions eo;
  eo.step_rad = 10 * M_PI / 180;
  const Samples s = extract_samples(src, scene, eo);
  const auto joint = joint_output_columns(scene);
  EXPECT_EQ(joint, (std::vector<std::string>{"p_crank", "k_crank", "r_crank", "p_lever", "k_lever", "r_lever"}));
  auto names = reduced_model_columns(scene);
  names.insert(names.end(), joint.begin(), joint.end());
  const auto whole = make_reduced_model(s, scene, Interpolation::Fourier);
  const auto part = make_reduced_model(select_columns(s, names), scene, Interpolation::Fourier);
  EXPECT_LT(part.table.cols, whole.table.cols);  // rx_F_crank is not read
  ReducedOptions ro;
  ro.duration_s = 0.5;
  ro.output_interval_s = 0.01;
  const auto base = simulate_reduced(whole, 0.1, 3.0, ro);
  auto a = base, b = base;
  add_joint_outputs(scene, whole, a);
  add_joint_outputs(scene, part, b);
  ASSERT_FALSE(a.column_names.empty());
  EXPECT_EQ(b.column_names, a.column_names);
  EXPECT_EQ(b.columns, a.columns);
  for (const auto& name : joint) {
    std::vector<std::string> fewer;
    for (const auto& n : names)
      if (n != name) fewer.push_back(n);
    auto c = base;
    const auto without = select_columns(s, fewer);
    EXPECT_THROW(add_joint_outputs(scene, make_reduced_model(without, scene, Interpolation::Fourier), c), TableError)
        << name;
  }
}

struct Csv {
  std::map<std::string, std::vector<double>> col;
};

Csv read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string f; std::getline(hs, f, ',');) names.push_back(f);
  Csv c;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    size_t k = 0;
    for (std::string f; std::getline(ls, f, ',') && k < names.size(); ++k) c.col[names[k]].push_back(std::stod(f));
  }
  return c;
}

int rdyn(const std::string& args) {
  const int st = std::system((std::string(RDYN_BINARY) + " " + args + " 2>/dev/null").c_str());
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// Largest difference over the run relative to the full model's peak of each output column.
std::map<std::string, double> agreement(const std::string& scene, const std::string& sets) {
  const auto dir = fs::temp_directory_path() / ("rdyn_joint_outputs_" + std::to_string(::getpid()));
  std::map<std::string, Csv> run;
  for (const char* model : {"full", "reduced"}) {
    const auto out = dir / model;
    EXPECT_EQ(rdyn("simulate " + scene + " --model " + model + " --duration 1 " + sets + " --out " + out.string() +
                   " --force"),
              0);
    run[model] = read_csv(out / "timeseries.csv");
  }
  fs::remove_all(dir);
  std::map<std::string, double> rel;
  const auto& F = run["full"].col;
  const auto& R = run["reduced"].col;
  for (const auto& [name, f] : F) {
    if (name == "t" || !R.count(name)) continue;
    const auto& r = R.at(name);
    EXPECT_EQ(r.size(), f.size()) << name;
    double peak = 0, err = 0;
    for (size_t i = 0; i < std::min(f.size(), r.size()); ++i)
      peak = std::max(peak, std::abs(f[i])), err = std::max(err, std::abs(f[i] - r[i]));
    rel[name] = err / std::max(peak, 1e-12);
  }
  for (const auto& [name, r] : R) EXPECT_TRUE(F.count(name)) << "reduced-only column " << name;
  return rel;
}

TEST(JointOutputsCli, FourbarBothModelsAgree) {
  // Measured at the default 10° Fourier table: every column within 1.1e-5 of its peak over 3 s.
  const auto rel =
      agreement("fourbar", "--set outputs.joints=all --set outputs.reactions=all --set outputs.shaking=true");
  for (const char* c : {"q_coupler", "qddot_rocker", "R_crank_x", "R_crank_y", "R_coupler_y", "R_rocker_x", "R_C_x",
                        "R_C_y", "shaking_x", "shaking_y", "shaking_M"}) {
    ASSERT_TRUE(rel.count(c)) << c;
    EXPECT_LT(rel.at(c), 1e-4) << c;
  }
}

TEST(JointOutputsCli, SliderCrankPinForcesAgree) {
  // Measured: every column within 1.2e-5 of its peak over 2 s.
  const auto rel =
      agreement("slider-crank", "--set outputs.joints=all --set outputs.reactions=all --set outputs.shaking=true");
  for (const char* c : {"q_slider", "qddot_slider", "qddot_rod", "R_crank_x", "R_crank_y", "R_rod_x", "R_wrist_pin_x",
                        "R_wrist_pin_y", "R_slider_x", "R_slider_y", "R_slider_normal", "shaking_x", "shaking_y",
                        "shaking_M"}) {
    ASSERT_TRUE(rel.count(c)) << c;
    EXPECT_LT(rel.at(c), 1e-4) << c;
  }
}


TEST(JointOutputsCli, ConstraintForceOnTheIndependentJointAgrees) {
  // The crank pin's force along the crank (A → B), a request on the independent joint: the
  // reduced model's constraint line against the full model's actuator multiplier. Measured
  // 8.1e-6 of its 119 N peak over 1 s.
  const auto rel = agreement("fourbar", "--set outputs.constraint_forces.rocker_axial.joint=crank --set "
                                        "outputs.constraint_forces.rocker_axial.direction=B");
  ASSERT_TRUE(rel.count("F_rocker_axial"));
  EXPECT_LT(rel.at("F_rocker_axial"), 1e-4);
}

// A motor geared 30:1 to the crank (tests/validate/scenes/shaper-qr.yaml, a quick-return shaper,
// issue #23): the motor's rotor turns 30 times per crank turn. Its centre of mass is on its axis
// and the gear acts on joint rates, not at its pin, so the pin holds exactly its weight:
// R_motor = (0, m g) at every instant. In the rotor's own frame that weight turns 30 times per
// turn of q, which the 36 points of a 10° table alias (it read up to 2 m g off, exit 0); the
// lines are tabulated in ground, where it is constant. The other columns against the full model.
TEST(JointOutputsCli, FastGearedRotorReactionDoesNotAliasOnA10DegreeTable) {
  const std::string scene = std::string(RDYN_TEST_SCENES) + "/shaper-qr.yaml";
  const auto dir = fs::temp_directory_path() / ("rdyn_geared_rotor_" + std::to_string(::getpid()));
  ASSERT_EQ(rdyn("simulate " + scene + " --model reduced --grid-deg 10 --duration 1 --out " + dir.string() + " --force"),
            0);
  const auto c = read_csv(dir / "timeseries.csv");
  fs::remove_all(dir);
  const double mg = 2.0 * 9.81;  // the rotor's mass (scene) times g
  ASSERT_TRUE(c.col.count("R_motor_x") && c.col.count("R_motor_y"));
  ASSERT_GT(c.col.at("R_motor_y").size(), 400u);
  for (size_t i = 0; i < c.col.at("R_motor_y").size(); ++i) {
    ASSERT_NEAR(c.col.at("R_motor_x")[i], 0.0, 1e-6 * mg) << "row " << i;
    ASSERT_NEAR(c.col.at("R_motor_y")[i], mg, 1e-6 * mg) << "row " << i;
  }
  // Every column the two models share, the crank's, the lever's and the ram's reactions among
  // them: measured ≤ 2.4e-4 of their peaks over 4 s (q̈ the largest); held to 1e-3.
  const auto rel = agreement(scene, "");
  for (const char* col : {"qddot", "R_motor_y", "R_crank_x", "R_lever_y", "R_ram_normal", "R_pin_x", "shaking_M"})
    EXPECT_TRUE(rel.count(col)) << col;
  for (const auto& [name, r] : rel) {
    if (name == "R_motor_x") continue;  // 0 in both (its peak): checked above
    EXPECT_LT(r, 1e-3) << name;
  }
}

}  // namespace
}  // namespace rdyn::reduced
