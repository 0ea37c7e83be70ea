// The C interface: errors as codes and messages, never an exception; the same numbers as the
// C++ runtime it wraps, field by field.
#include "reduced/rdyn_reduced.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <set>
#include <string>

#include "cli_table.hpp"
#include "pendulum_table.hpp"
#include "reduced/runtime.hpp"

namespace rdyn::reduced {
namespace {

namespace fs = std::filesystem;

// Tables written by the CLI once for the whole suite: the bicycle (drive torques, a knee
// force) and the fourbar (no drive torque).
class CApi : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("rdyn_c_api_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    ASSERT_EQ(test::extract_table_with_cli("bicycle", "10", bicycle()), 0);
    ASSERT_EQ(test::extract_table_with_cli("fourbar", "30", fourbar()), 0);
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string bicycle() { return (dir_ / "bicycle.csv").string(); }
  static std::string fourbar() { return (dir_ / "fourbar.csv").string(); }
  static fs::path dir_;
};
fs::path CApi::dir_;

TEST_F(CApi, LoadErrorsAreCodesWithMessages) {
  char msg[512];
  rdyn_model* m = reinterpret_cast<rdyn_model*>(0x1);  // must be reset to NULL on failure
  EXPECT_EQ(rdyn_model_load((dir_ / "missing.csv").c_str(), "bicycle", &m, msg, sizeof msg),
            RDYN_BAD_INPUT);
  EXPECT_EQ(m, nullptr);
  EXPECT_NE(std::string(msg).find("missing.csv"), std::string::npos) << msg;
  // A table of another scene.
  EXPECT_EQ(rdyn_model_load(fourbar().c_str(), "bicycle", &m, msg, sizeof msg), RDYN_BAD_INPUT);
  EXPECT_NE(std::string(msg).find("was extracted from a different scene"), std::string::npos)
      << msg;
  EXPECT_EQ(rdyn_model_load(bicycle().c_str(), "no-such-scene", &m, msg, sizeof msg),
            RDYN_BAD_INPUT);
  EXPECT_NE(std::string(msg).find("no such scene file"), std::string::npos) << msg;
  // The message is truncated to the buffer, NUL-terminated; a NULL buffer is allowed.
  char small[8];
  std::memset(small, 'x', sizeof small);
  EXPECT_EQ(rdyn_model_load(fourbar().c_str(), "bicycle", &m, small, sizeof small), RDYN_BAD_INPUT);
  EXPECT_EQ(std::strlen(small), 7u);
  EXPECT_EQ(rdyn_model_load(fourbar().c_str(), "bicycle", &m, nullptr, 0), RDYN_BAD_INPUT);
  // Null arguments.
  EXPECT_EQ(rdyn_model_load(nullptr, "bicycle", &m, msg, sizeof msg), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_model_load(bicycle().c_str(), nullptr, &m, msg, sizeof msg), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_model_load(bicycle().c_str(), "bicycle", nullptr, msg, sizeof msg),
            RDYN_BAD_ARGUMENT);
  rdyn_model_free(nullptr);
  rdyn_workspace_free(nullptr);
}

TEST_F(CApi, StepsLikeTheCxxRuntimeFieldByField) {
  char msg[512];
  rdyn_model* m = nullptr;
  ASSERT_EQ(rdyn_model_load(bicycle().c_str(), "bicycle", &m, msg, sizeof msg), RDYN_OK) << msg;
  rdyn_workspace* ws = nullptr;
  ASSERT_EQ(rdyn_workspace_new(m, &ws), RDYN_OK);
  const auto model = load_runtime_model(bicycle(), "bicycle");
  RuntimeWorkspace cxx(model);

  double q0, qd0;
  ASSERT_EQ(rdyn_model_initial_state(m, &q0, &qd0), RDYN_OK);
  EXPECT_EQ(q0, model.initial_q);
  EXPECT_EQ(qd0, model.initial_qdot);
  ASSERT_EQ(rdyn_model_num_forces(m), 1);
  EXPECT_STREQ(rdyn_model_force_name(m, 0), "knee");
  EXPECT_EQ(rdyn_model_force_name(m, 1), nullptr);
  EXPECT_EQ(rdyn_model_force_name(m, -1), nullptr);
  ASSERT_EQ(rdyn_model_num_drive_torques(m), 2);  // both hips
  double nominal = 0;
  ASSERT_EQ(rdyn_model_drive_torque(m, 1, &nominal), RDYN_OK);
  EXPECT_EQ(nominal, model.drive_nominal[1]);
  ASSERT_EQ(rdyn_model_drive_torque(m, 0, &nominal), RDYN_OK);
  EXPECT_EQ(rdyn_model_drive_torque(m, 2, &nominal), RDYN_BAD_ARGUMENT);

  // Both modes of the drive, alternating, from a state that is not the scene's.
  ASSERT_EQ(rdyn_reset(m, ws, 1.0, 5.0, {RDYN_DRIVE_SCALE, 0.5}), RDYN_OK);
  ASSERT_EQ(reset(model, cxx, 1.0, 5.0, Drive::scaled(0.5)), Status::Ok);
  for (int i = 0; i < 1500; ++i) {
    const double value = 40.0 + 20.0 * std::sin(1e-2 * i);
    const rdyn_drive d = i % 2 ? rdyn_drive{RDYN_DRIVE_TORQUE, value}
                               : rdyn_drive{RDYN_DRIVE_SCALE, value / nominal};
    ASSERT_EQ(rdyn_step(m, ws, 1e-3, d), RDYN_OK);
    ASSERT_EQ(step(model, cxx, 1e-3, i % 2 ? Drive::torque(value) : Drive::scaled(value / nominal)),
              Status::Ok);
  }
  rdyn_state st;
  ASSERT_EQ(rdyn_get_state(ws, &st), RDYN_OK);
  EXPECT_EQ(st.t, cxx.get_t());
  EXPECT_EQ(st.q, cxx.get_q());
  EXPECT_EQ(st.qdot, cxx.get_qdot());
  EXPECT_EQ(st.qddot, cxx.get_qddot());
  EXPECT_EQ(st.work, cxx.get_work());
  EXPECT_EQ(st.energy, cxx.get_energy());
  EXPECT_GT(st.q, 1.0 + 2 * M_PI);  // more than a turn: gates switched along the way
  double f[3] = {NAN, NAN, -7.0};
  ASSERT_EQ(rdyn_get_forces(ws, f, 3), RDYN_OK);  // copies only the one force there is
  EXPECT_EQ(f[0], cxx.get_forces()[0]);
  EXPECT_TRUE(std::isnan(f[1]));
  EXPECT_EQ(rdyn_get_forces(ws, f, -1), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_get_forces(ws, nullptr, 1), RDYN_BAD_ARGUMENT);
  // The bicycle asks for no joint output: none, and copying none is fine.
  EXPECT_EQ(rdyn_model_num_joint_outputs(m), 0);
  EXPECT_EQ(rdyn_model_joint_output_name(m, 0), nullptr);
  EXPECT_EQ(rdyn_get_joint_outputs(ws, f, 3), RDYN_OK);
  EXPECT_TRUE(std::isnan(f[1]));

  // Refusals are the C++ statuses, and change nothing.
  EXPECT_EQ(rdyn_step(m, ws, NAN, {RDYN_DRIVE_SCALE, 1.0}), RDYN_BAD_STEP);
  EXPECT_EQ(rdyn_step(m, ws, 1e-3, {RDYN_DRIVE_TORQUE, 2e6}), RDYN_BAD_DRIVE);
  EXPECT_NE(std::string(rdyn_workspace_message(ws, RDYN_BAD_DRIVE)).find("exceeds 1e6"), std::string::npos);
  EXPECT_EQ(rdyn_step(m, ws, 1e-3, {7, 1.0}), RDYN_BAD_DRIVE);
  EXPECT_NE(std::string(rdyn_workspace_message(ws, RDYN_BAD_DRIVE)).find("mode is unknown"), std::string::npos);
  EXPECT_STREQ(rdyn_workspace_message(nullptr, RDYN_BAD_STEP), rdyn_status_string(RDYN_BAD_STEP));
  EXPECT_EQ(rdyn_reset(m, ws, NAN, 0.0, {RDYN_DRIVE_SCALE, 1.0}), RDYN_BAD_STATE);
  rdyn_state again;
  ASSERT_EQ(rdyn_get_state(ws, &again), RDYN_OK);
  EXPECT_EQ(std::memcmp(&st, &again, sizeof st), 0);
  EXPECT_EQ(rdyn_step(nullptr, ws, 1e-3, {RDYN_DRIVE_SCALE, 1.0}), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_step(m, nullptr, 1e-3, {RDYN_DRIVE_SCALE, 1.0}), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_get_state(ws, nullptr), RDYN_BAD_ARGUMENT);

  // A workspace of the fourbar is not the bicycle's.
  rdyn_model* fb = nullptr;
  rdyn_workspace* fb_ws = nullptr;
  ASSERT_EQ(rdyn_model_load(fourbar().c_str(), "fourbar", &fb, msg, sizeof msg), RDYN_OK) << msg;
  ASSERT_EQ(rdyn_workspace_new(fb, &fb_ws), RDYN_OK);
  EXPECT_EQ(rdyn_step(m, fb_ws, 1e-3, {RDYN_DRIVE_SCALE, 1.0}), RDYN_WRONG_WORKSPACE);
  EXPECT_EQ(rdyn_step(fb, fb_ws, 1e-3, {RDYN_DRIVE_SCALE, 1.0}), RDYN_OK);
  rdyn_workspace* none = reinterpret_cast<rdyn_workspace*>(0x1);  // must be reset to NULL
  EXPECT_EQ(rdyn_workspace_new(nullptr, &none), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(none, nullptr);

  rdyn_workspace_free(ws);
  rdyn_workspace_free(fb_ws);
  rdyn_model_free(m);
  rdyn_model_free(fb);
}

// The joint outputs through C: names and count as the C++ model's, the values the C++ runtime's
// after the same steps, field by field (the C++ values are checked against closed forms and
// `rdyn simulate` rows in runtime_test.cpp), and the pendulum's pivot reaction while it hangs.
TEST_F(CApi, JointOutputsAreTheCxxRuntimesAndThePivotsClosedForm) {
  const fs::path pdir = dir_ / "joint-outputs";
  ASSERT_EQ(test::write_pendulum_table(pdir), 0);
  const std::string table = (pdir / "pendulum.csv").string(), scene = (pdir / "pendulum.yaml").string();
  char msg[512];
  rdyn_model* m = nullptr;
  ASSERT_EQ(rdyn_model_load(table.c_str(), scene.c_str(), &m, msg, sizeof msg), RDYN_OK) << msg;
  const auto model = load_runtime_model(table, scene);
  ASSERT_EQ(rdyn_model_num_joint_outputs(m), 8);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(rdyn_model_joint_output_name(m, k), model.joint_outputs->names[k]);
  EXPECT_STREQ(rdyn_model_joint_output_name(m, 4), "R_pivot_y");
  EXPECT_EQ(rdyn_model_joint_output_name(m, 8), nullptr);
  EXPECT_EQ(rdyn_model_joint_output_name(m, -1), nullptr);
  EXPECT_EQ(rdyn_model_num_forces(m), 0);  // the reaction lines are not the scene's forces
  rdyn_workspace* ws = nullptr;
  ASSERT_EQ(rdyn_workspace_new(m, &ws), RDYN_OK);
  // Hanging at ω = 2 rad/s: R_y = m (g + l ω²).
  ASSERT_EQ(rdyn_reset(m, ws, -M_PI / 2, 2.0, {RDYN_DRIVE_SCALE, 1.0}), RDYN_OK);
  double o[9];
  o[8] = -7.0;
  ASSERT_EQ(rdyn_get_joint_outputs(ws, o, 9), RDYN_OK);  // copies the eight there are
  EXPECT_EQ(o[8], -7.0);
  const double m_kg = test::kPendulumMass_kg, l = test::kPendulumArm_m;
  EXPECT_NEAR(o[4], m_kg * (9.81 + l * 4.0), 1e-9 * m_kg * 9.81);
  EXPECT_NEAR(o[3], 0.0, 1e-9 * m_kg * 9.81);
  RuntimeWorkspace cxx(model);
  ASSERT_EQ(reset(model, cxx, -M_PI / 2, 2.0), Status::Ok);
  for (int i = 0; i < 700; ++i) {
    ASSERT_EQ(rdyn_step(m, ws, 1e-3, {RDYN_DRIVE_SCALE, 1.0}), RDYN_OK);
    ASSERT_EQ(step(model, cxx, 1e-3, Drive{}), Status::Ok);
  }
  ASSERT_EQ(rdyn_get_joint_outputs(ws, o, 8), RDYN_OK);
  for (int k = 0; k < 8; ++k) EXPECT_EQ(o[k], cxx.get_joint_outputs()[k]) << model.joint_outputs->names[k];
  EXPECT_EQ(rdyn_get_joint_outputs(ws, o, -1), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_get_joint_outputs(ws, nullptr, 1), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_get_joint_outputs(nullptr, o, 1), RDYN_BAD_ARGUMENT);
  rdyn_workspace_free(ws);
  rdyn_model_free(m);
}

// A body on a pivot with gravity and a viscous bearing: m = 2 kg, centre of mass l = 0.3 m from
// the pivot, I_G = 0.01 kg·m², so I = I_G + m l² = 0.19 kg·m² about the pivot and
//   drive = I q̈ + m g l cos q + c q̇   (q from the x axis, gravity along −y, c = 0.02 N·m·s).
constexpr double kPendulumI = 0.19, kPendulumMgl = 2 * 9.81 * 0.3, kPendulumC = 0.02;
constexpr const char* kPendulumYaml = R"(name: pivot-pendulum
ground_points: {O: [0, 0]}
bodies:
  - {name: arm, mass_kg: 2, com_m: [0.3, 0], inertia_kgm2: 0.01}
joints:
  - {name: pivot, type: revolute, parent: ground, parent_point: O, child: arm}
independent: pivot
loads:
  - {type: resistance, name: bearing, body: arm, law: viscous, coefficient: 0.02}
gravity: {enabled: true, g_m_s2: [0, -9.81]}
initial: {q_deg: 20, qdot: 3.0}
simulation: {duration_s: 2, output_interval_s: 0.01}
)";

// The rows of a CSV with a header line: column name → values.
std::map<std::string, std::vector<double>> read_csv_columns(const fs::path& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string n; std::getline(header, n, ',');) names.push_back(n);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string v;
    for (size_t c = 0; c < names.size() && std::getline(row, v, ','); ++c) cols[names[c]].push_back(std::stod(v));
  }
  return cols;
}

// rdyn_drive_torque against the pendulum's closed form, and against `rdyn drive --model
// reduced` (a profile with q̈ ≠ 0 through both signs of q̇) row by row: the same drive.
TEST_F(CApi, DriveTorqueIsThePendulumsClosedFormAndTheDriveCommandsRows) {
  const fs::path scene = dir_ / "pendulum.yaml", table = dir_ / "pendulum.csv", profile = dir_ / "profile.csv";
  std::ofstream(scene) << kPendulumYaml;
  {
    std::ofstream p(profile);
    p << "t,q_deg\n";
    for (int i = 0; i <= 40; ++i) {  // q = 20° + 300° sin(πt) over 2 s: q̇ changes sign
      const double t = 0.05 * i;
      p << t << "," << 20 + 300 * std::sin(M_PI * t) << "\n";
    }
  }
  ASSERT_EQ(test::extract_table_with_cli(scene.string(), "10", table.string()), 0);
  ASSERT_EQ(test::run_rdyn_cli({"drive", scene.string(), "--profile", profile.string(), "--model", "reduced",
                                "--grid-deg", "10", "--dt-out", "0.01", "--out", (dir_ / "drive").string(), "--force"}),
            0);
  char msg[512];
  rdyn_model* m = nullptr;
  ASSERT_EQ(rdyn_model_load(table.c_str(), scene.c_str(), &m, msg, sizeof msg), RDYN_OK) << msg;
  rdyn_workspace* ws = nullptr;
  ASSERT_EQ(rdyn_workspace_new(m, &ws), RDYN_OK);
  const auto rows = read_csv_columns(dir_ / "drive" / "timeseries.csv");
  const auto& q = rows.at("q");
  ASSERT_EQ(q.size(), 201u);
  double worst_cli = 0.0, worst_closed = 0.0, peak = 0.0;
  for (size_t i = 0; i < q.size(); ++i) {
    const double qd = rows.at("qdot")[i], qdd = rows.at("qddot")[i], want = rows.at("drive_Nm")[i];
    double d = NAN;
    ASSERT_EQ(rdyn_drive_torque(m, ws, q[i], qd, qdd, &d), RDYN_OK) << i;
    worst_cli = std::max(worst_cli, std::abs(d - want) / (1 + std::abs(want)));
    const double closed = kPendulumI * qdd + kPendulumMgl * std::cos(q[i]) + kPendulumC * qd;
    worst_closed = std::max(worst_closed, std::abs(d - closed));
    peak = std::max(peak, std::abs(closed));
  }
  EXPECT_LT(worst_cli, 1e-9);
  // A 10° Fourier table of constant m1 and m g l cos q is exact up to the extraction's rounding.
  EXPECT_LT(worst_closed, 1e-8 * peak) << "peak " << peak;
  EXPECT_GT(peak, 10.0);  // I q̈ reaches 0.19·(300° in rad)·π² ≈ 9.8, m g l = 5.9, c q̇ ≈ 0.3
  // Refusals: null pointers, a state outside the checks; *drive untouched.
  double d = 7.0;
  EXPECT_EQ(rdyn_drive_torque(m, ws, 0.1, 1.0, 0.0, nullptr), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_drive_torque(nullptr, ws, 0.1, 1.0, 0.0, &d), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_drive_torque(m, nullptr, 0.1, 1.0, 0.0, &d), RDYN_BAD_ARGUMENT);
  EXPECT_EQ(rdyn_drive_torque(m, ws, NAN, 1.0, 0.0, &d), RDYN_BAD_STATE);
  EXPECT_EQ(rdyn_drive_torque(m, ws, 0.1, 1.0, INFINITY, &d), RDYN_BAD_STATE);
  EXPECT_EQ(d, 7.0);
  rdyn_workspace_free(ws);
  rdyn_model_free(m);
}

TEST(CApiStatus, EveryStatusHasItsOwnSentence) {
  const rdyn_status all[] = {
      RDYN_OK,         RDYN_BAD_STEP,      RDYN_BAD_DRIVE, RDYN_BAD_STATE,    RDYN_WRONG_WORKSPACE,
      RDYN_NON_FINITE, RDYN_LEFT_TABLE,    RDYN_DIVERGED,  RDYN_BAD_ARGUMENT, RDYN_BAD_INPUT,
      RDYN_NUMERICAL,  RDYN_OUT_OF_MEMORY, RDYN_INTERNAL};
  std::set<std::string> seen;
  for (rdyn_status s : all) {
    const std::string text = rdyn_status_string(s);
    EXPECT_NE(text, "unknown status") << s;
    EXPECT_TRUE(seen.insert(text).second) << "duplicate sentence for " << s;
  }
  EXPECT_STREQ(rdyn_status_string(-3), "unknown status");
  EXPECT_STREQ(rdyn_status_string(12), "unknown status");
}

}  // namespace
}  // namespace rdyn::reduced
