// Prescribed motion (validate/analysis/drive, `rdyn drive`): closed forms, the two models against each
// other, a profile against the constant rate it describes, and the command's contract.
#include "validate/analysis/drive.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "models/scene_yaml.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"
#include "tests/validate/run_rdyn.hpp"
#include "validate/analysis/build_reduced.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

reduced::ReducedModel reduced_of(const models::Scene& scene, double grid_deg) {
  const auto e = extract_from_full(scene, grid_deg, reduced::Method::Kinetostatic);
  return reduced::make_reduced_model(e.samples, scene, reduced::Interpolation::Fourier);
}

// The hard parallelogram has constant m1, m2 = 0 and no losses; its gravity term is
// Q_cons = −k cos q with k = g (m_crank·0.05 + m_rocker·0.05 + m_coupler·a). At a constant rate
// the drive only holds gravity: drive = −Q_cons = k cos q (positive where the crank points along
// +x: gravity pulls it down, the drive lifts).
TEST(Drive, ParallelogramAtConstantRateHoldsGravityOnly) {
  const auto scene = models::load_scene(RDYN_SCENES "/hard/parallelogram.yaml");
  const double k = 9.81 * (0.5 * 0.05 + 0.7 * 0.05 + 1.2 * 0.1);
  const auto motion = constant_rate_motion(scene.initial.q, 2 * M_PI * 2.0, 1.0, 0.005);  // two turns
  const auto full = calc_drive_full(scene, motion);
  const auto red = calc_drive_reduced(reduced_of(scene, 10), motion);
  ASSERT_EQ(full.drive.size(), motion.t.size());
  for (size_t i = 0; i < motion.t.size(); ++i) {
    // ~5e-7 at the aligned (singular) positions, where the constraint split is least squares.
    EXPECT_NEAR(full.drive[i], k * std::cos(motion.q[i]), 1e-6 * k) << motion.t[i];
    EXPECT_NEAR(red.drive[i], k * std::cos(motion.q[i]), 1e-6 * k) << motion.t[i];
    EXPECT_DOUBLE_EQ(full.power[i], full.drive[i] * motion.qdot[i]);
  }
  // Over whole turns gravity does no net work: mean drive power 0, RMS k/√2.
  const auto st = calc_drive_stats(full);
  EXPECT_NEAR(st.mean_power_W, 0.0, 1e-6 * k * motion.qdot[0]);
  EXPECT_NEAR(st.rms, k / std::sqrt(2.0), 1e-4 * k);
  EXPECT_NEAR(st.peak, k, 1e-3 * k);  // rows 3.6° apart: the sampled peak is within 1 − cos 1.8°
}

// The shaking load of the parallelogram turned at a constant rate ω, in closed form: every
// centre of mass moves on a circle about its pivot (the coupler translates), so Σ m a_com =
// −ω² (0.5·0.05 + 1.2·0.1 + 0.7·0.05) (cos q, sin q) and the load on the ground is
// Σ m g − Σ m a_com = (0.18 ω² cos q, −2.4 g + 0.18 ω² sin q). Both models give it as a column of
// the drive, through the aligned positions.
TEST(Drive, JointOutputsOfTheParallelogramAtConstantRateAreItsClosedForm) {
  auto scene = models::load_scene(RDYN_SCENES "/hard/parallelogram.yaml", {{"outputs.shaking", "true"}});
  const double w = 2 * M_PI * 2.0, c = 0.5 * 0.05 + 1.2 * 0.1 + 0.7 * 0.05, g = 9.81;
  const auto motion = constant_rate_motion(scene.initial.q, w, 1.0, 0.005);
  const auto full = calc_drive_full(scene, motion);
  const auto red = calc_drive_reduced(scene, reduced_of(reduced::with_reaction_requests(scene), 10), motion);
  for (const auto* r : {&full, &red}) {
    ASSERT_EQ(r->column_names, (std::vector<std::string>{"shaking_x", "shaking_y", "shaking_M"}));
    for (size_t i = 0; i < motion.t.size(); ++i) {
      const double q = motion.q[i];
      EXPECT_NEAR(r->columns[0][i], c * w * w * std::cos(q), 1e-6 * c * w * w) << motion.t[i];
      EXPECT_NEAR(r->columns[1][i], -2.4 * g + c * w * w * std::sin(q), 1e-6 * c * w * w) << motion.t[i];
    }
  }
}

// A motor line against the parallelogram's drive k cos q at a constant rate ω: the line gives
// stall·(1 − ω/ω0) at every row, so the smallest margin is that minus the largest drive, at
// the crank's +x position (q = 0 mod 2π); a weaker motor misses by the same algebra. Turning
// backwards with a reversed motor (negative stall and speed) the margin is drive − line.
TEST(Drive, AMotorLineCoversTheDriveWithTheClosedFormMargin) {
  const auto scene = models::load_scene(RDYN_SCENES "/hard/parallelogram.yaml");
  const double k = 9.81 * (0.5 * 0.05 + 0.7 * 0.05 + 1.2 * 0.1), w = 2 * M_PI;
  const auto forward = calc_drive_full(scene, constant_rate_motion(scene.initial.q, w, 1.0, 0.001));
  const double peak = *std::max_element(forward.drive.begin(), forward.drive.end());
  EXPECT_NEAR(peak, k, 1e-5 * k);
  for (const double stall : {5.0, 1.0}) {
    const auto c = calc_motor_check(forward, stall, 20.0);
    const double line = stall * (1 - w / 20.0);
    EXPECT_NEAR(c.min_margin, line - peak, 1e-12) << stall;
    EXPECT_EQ(c.covers, line > k) << stall;  // 3.43 N·m covers k = 1.77; 0.69 does not
    EXPECT_NEAR(std::remainder(c.at_q, 2 * M_PI), 0.0, 0.5 * w * 0.001 + 1e-9) << stall;  // the row nearest 0
    EXPECT_DOUBLE_EQ(c.line_there, line);
  }
  const auto backward = calc_drive_full(scene, constant_rate_motion(scene.initial.q, -w, 1.0, 0.001));
  const double low = *std::min_element(backward.drive.begin(), backward.drive.end());
  const auto c = calc_motor_check(backward, -5.0, -20.0);
  EXPECT_NEAR(c.min_margin, low - (-5.0 * (1 - w / 20.0)), 1e-12);
  EXPECT_TRUE(c.covers);
}

// A row exactly at an aligned (singular) position: the constraint split there is least squares,
// so the full model takes the drive's limit along the branch from both sides (it gave 0.31 k).
// The chain of 3 parallelograms the same at its flat rows: k = g [(N+1)/2 + N].
TEST(Drive, FullModelAtASingularRowTakesTheBranchLimit) {
  const auto scene = models::load_scene(RDYN_SCENES "/hard/parallelogram.yaml");
  const double k = 9.81 * (0.5 * 0.05 + 0.7 * 0.05 + 1.2 * 0.1);
  const auto motion = constant_rate_motion(scene.initial.q, 2 * M_PI, 0.5, 1.0 / 24);  // 15° rows through 180°
  const auto full = calc_drive_full(scene, motion);
  bool singular_row = false;
  for (size_t i = 0; i < motion.t.size(); ++i) {
    singular_row |= std::abs(std::remainder(motion.q[i], M_PI)) < 1e-12;
    EXPECT_NEAR(full.drive[i], k * std::cos(motion.q[i]), 1e-6 * k) << motion.t[i];
  }
  EXPECT_TRUE(singular_row);
  const auto chain = models::load_scene(RDYN_SCENES "/chains/chain-3.yaml");
  const double kc = 9.81 * (4 / 2.0 + 3);
  const auto cm = constant_rate_motion(chain.initial.q, 2 * M_PI, 1.0, 0.25);  // 90°, 180°, 270°, 360°, 450°
  const auto cf = calc_drive_full(chain, cm);
  for (size_t i = 0; i < cm.t.size(); ++i) EXPECT_NEAR(cf.drive[i], kc * std::cos(cm.q[i]), 1e-6 * kc) << cm.t[i];
}

// The bicycle with its hip torque gate, brake and knee force: full inverse dynamics against the
// 5° table's inverse Eksergian equation, both ways through the gate switches.
TEST(Drive, AProfileStartingOnTheSingularConfigurationTakesItsLimitThere) {
  // The isosceles slider-crank driven from its slider, q(t) = 0.1 sin(πt) m: it starts on the
  // folded position (rank loss at q = 0), where the velocity projection itself fails. There the
  // drive is its limit, 0 by symmetry: q̈(0) = 0 (the natural spline), the centering spring at its
  // rest length, and m2 = ½ dm1/dq = 0 at the symmetric configuration. It was an EngineError in
  // Simbody's words.
  const fs::path dir = fs::temp_directory_path() / ("rdyn_drive_singular_" + std::to_string(getpid()));
  fs::create_directories(dir);
  {
    std::ofstream p(dir / "p.csv");
    p << "t,q_m\n";
    for (int i = 0; i <= 100; ++i) p << fmt::format("{},{:.17g}\n", 0.01 * i, 0.1 * std::sin(M_PI * 0.01 * i));
  }
  const auto scene = models::load_scene(RDYN_SOURCE_DIR "/tests/validate/scenes/iso-slider-crank.yaml");
  const auto motion = profile_motion((dir / "p.csv").string(), false, 1.0, 0.01);
  const auto full = calc_drive_full(scene, motion);
  ASSERT_EQ(full.drive.size(), motion.t.size());
  double peak = 0.0;
  for (double d : full.drive) peak = std::max(peak, std::abs(d));
  EXPECT_GT(peak, 10.0);
  EXPECT_LT(std::abs(full.drive[0]), 1e-7 * peak) << full.drive[0];
  for (double f : full.forces[0]) EXPECT_TRUE(std::isfinite(f));
  fs::remove_all(dir);
}

// Through the same folded position accelerating (q̈ = 0.1 m/s² there), the rod force has its pole
// (me1 ≈ 0.026/x kg times q̈): the symmetric limit is a finite principal value with no branch
// behind it, so the row is refused (exit 1 in the CLI), as the reduced model refuses its band.
TEST(Drive, AForceWithAPoleAtASingularRowIsRefusedThere) {
  const fs::path dir = fs::temp_directory_path() / ("rdyn_drive_pole_" + std::to_string(getpid()));
  fs::create_directories(dir);
  {
    std::ofstream p(dir / "p.csv");
    p << "t,q_m\n";
    for (int i = 0; i <= 100; ++i) {
      const double t = 0.01 * i - 0.5;  // q = 0 exactly on the row at t = 0.5 s
      p << fmt::format("{},{:.17g}\n", 0.01 * i, 0.1 * t + 0.05 * t * t);
    }
  }
  const auto scene = models::load_scene(RDYN_SOURCE_DIR "/tests/validate/scenes/iso-slider-crank.yaml");
  const auto motion = profile_motion((dir / "p.csv").string(), false, 1.0, 0.01);
  try {
    calc_drive_full(scene, motion);
    ADD_FAILURE() << "the principal value at the pole was given as the rod force";
  } catch (const models::NumericalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("constraint force 'rod_axial' grows without bound at t = 0.5 s"), std::string::npos) << m;
  }
  // The same fold between two rows (q = 0 at t = 0.505 s, rows 10 ms apart): no row shows the
  // pole, and the rows' peak depended on --dt-out; it is found from the scan and refused.
  {
    std::ofstream p(dir / "between.csv");
    p << "t,q_m\n";
    for (int i = 0; i <= 100; ++i) {
      const double t = 0.01 * i - 0.505;
      p << fmt::format("{},{:.17g}\n", 0.01 * i, 0.1 * t + 0.05 * t * t);
    }
  }
  try {
    calc_drive_full(scene, profile_motion((dir / "between.csv").string(), false, 1.0, 0.01));
    ADD_FAILURE() << "a pole between two rows gave finite rows";
  } catch (const models::NumericalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("constraint force 'rod_axial' grows without bound at t = 0.50"), std::string::npos) << m;
    EXPECT_NE(m.find("between two output rows"), std::string::npos) << m;
  }
  // A motion that never reaches the fold is not refused (the guard fires only where it must).
  {
    std::ofstream p(dir / "short.csv");
    p << "t,q_m\n";
    for (int i = 0; i <= 100; ++i) p << fmt::format("{},{:.17g}\n", 0.01 * i, 0.05 + 0.1 * 0.01 * i);
  }
  EXPECT_EQ(calc_drive_full(scene, profile_motion((dir / "short.csv").string(), false, 1.0, 0.01)).drive.size(), 101u);
  fs::remove_all(dir);
}

TEST(Drive, BicycleFullAndReducedAgree) {
  const auto scene = models::load_scene("bicycle");
  const auto motion = constant_rate_motion(scene.initial.q, 2 * M_PI * 1.0, 1.0, 0.002);
  const auto full = calc_drive_full(scene, motion);
  const auto red = calc_drive_reduced(reduced_of(scene, 5), motion);
  const auto sf = calc_drive_stats(full);
  ASSERT_EQ(full.force_names, red.force_names);
  ASSERT_FALSE(full.forces.empty());
  for (size_t i = 0; i < motion.t.size(); ++i) {
    EXPECT_NEAR(red.drive[i], full.drive[i], 1e-4 * sf.peak) << motion.t[i];
    EXPECT_NEAR(red.forces[0][i], full.forces[0][i], 1e-4 * sf.force_peaks[0]) << motion.t[i];
  }
  EXPECT_GT(sf.peak, 1.0);  // it does work against the brake and gravity
}

// A profile q(t) = q0 + ωt (a natural cubic spline of a straight line is the line) gives the
// constant rate's drive; malformed profiles are refused naming the line.
TEST(Drive, ProfileOfAConstantRateIsTheConstantRate) {
  const auto scene = models::load_scene(RDYN_SCENES "/hard/parallelogram.yaml");
  const fs::path dir = fs::temp_directory_path() / fmt::format("rdyn_drive_{}", ::getpid());
  fs::create_directories(dir);
  const double w = 2 * M_PI * 0.8;
  {
    std::ofstream f(dir / "p.csv");
    f << "# a line\nt,q_deg\n";
    for (int i = 0; i <= 50; ++i) f << fmt::format("{:.17g},{:.17g}\n", 0.02 * i, (scene.initial.q + w * 0.02 * i) * 180 / M_PI);
  }
  const auto prof = profile_motion((dir / "p.csv").string(), true, std::nullopt, 0.01);
  const auto cr = constant_rate_motion(scene.initial.q, w, 1.0, 0.01);
  ASSERT_EQ(prof.t.size(), cr.t.size());
  for (size_t i = 0; i < cr.t.size(); ++i) {
    EXPECT_NEAR(prof.q[i], cr.q[i], 1e-12);
    EXPECT_NEAR(prof.qdot[i], w, 1e-9 * w);
    EXPECT_NEAR(prof.qddot[i], 0.0, 1e-8 * w);
  }
  auto refused = [&](const std::string& text, const std::string& field, int line) {
    std::ofstream(dir / "bad.csv") << text;
    try {
      profile_motion((dir / "bad.csv").string(), true, std::nullopt, 0.01);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const models::SceneError& e) {
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_EQ(e.line(), line) << e.what();
    }
  };
  refused("t,q_deg\n0,0\n1,10\n0.5,20\n2,30\n", "t", 4);       // time going back
  refused("t,q_m\n0,0\n1,1\n2,2\n3,3\n", "header", 1);          // metres for a revolute coordinate
  refused("t,q_deg\n0,0\n1,nan\n2,2\n3,3\n", "row", 3);         // not finite
  refused("t,q_deg\n0,0\n1,1\n2,2\n", "rows", 4);               // too few rows
  refused("t,q_deg\n0,30\n1e-300,31\n1,60\n2,90\n", "t", 3);  // rows closer than 1 µs (was exit 1)
  // An editor's byte-order mark and CR-only line ends read as the plain file.
  std::string plain = "t,q_deg\n0,0\n0.5,10\n1,20\n1.5,30\n";
  std::ofstream(dir / "bom.csv") << "\xEF\xBB\xBF" + plain;
  std::string cr_only = plain;
  std::replace(cr_only.begin(), cr_only.end(), '\n', '\r');
  std::ofstream(dir / "cr.csv") << cr_only;
  std::ofstream(dir / "plain.csv") << plain;
  const auto want = profile_motion((dir / "plain.csv").string(), true, std::nullopt, 0.01);
  for (const char* f : {"bom.csv", "cr.csv"}) {
    const auto got = profile_motion((dir / f).string(), true, std::nullopt, 0.01);
    EXPECT_EQ(got.q, want.q) << f;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rdyn::validate
