// extract_from_full: the table and its timing by stage (summary.json extraction_stages_ms).
#include "validate/analysis/build_reduced.hpp"
#include "reduced/samples.hpp"
#include "reduced/extract.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <unistd.h>
#include <filesystem>
#include <string>

#include "models/scene_yaml.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/table_resolution.hpp"

namespace rdyn::validate {
namespace {

void expect_stages_add_up(const Extraction& e) {
  EXPECT_GT(e.stages.system_build_ms, 0.0);
  EXPECT_GT(e.stages.assembly_ms, 0.0);
  EXPECT_GT(e.stages.kinetostatics_ms, 0.0);
  EXPECT_NEAR(e.stages.system_build_ms + e.stages.assembly_ms + e.stages.kinetostatics_ms, e.extraction_ms,
              1e-9 * e.extraction_ms);
}

TEST(BuildReduced, PeriodicExtractionTimesEachStage) {
  const auto e = extract_from_full(models::load_scene("bicycle"), 10, reduced::Method::Kinetostatic);
  EXPECT_EQ(e.samples.q.size(), 36u);
  EXPECT_FALSE(e.range);
  expect_stages_add_up(e);
  // One projection per grid point plus a few per switch angle (4 angles): the separate calls
  // needed 99.
  EXPECT_LE(e.calls, 36 + 4 * 4);
}

TEST(BuildReduced, RangeExtractionTimesEachStage) {
  // A rocker: the full-turn attempt meets a dead point, the range comes from the dead points.
  const auto e = extract_from_full(models::load_scene("fourbar-rocker"), 10, reduced::Method::Kinetostatic);
  ASSERT_TRUE(e.range);
  EXPECT_FALSE(e.samples.periodic);
  expect_stages_add_up(e);
}

// A non-Grashof four-bar whose crank is blocked over only ~2° near 180° (crank 0.18004 m, the
// ground pivot turned 2.5°): the 10° sweep steps over the blocked range onto the other assembly
// and would call the table periodic. One more sample a turn later does not match the first
// (the sweep did not close), so the dead points are looked for and the range between them is
// sampled instead, on the assembled branch.
TEST(BuildReduced, ASweepThatChangesBranchBecomesARangeTable) {
  const auto scene = models::load_scene("fourbar", {{"bodies.crank.points.B.0", "0.18004"},
                                                    {"ground_points.D.0", "0.299714"},
                                                    {"ground_points.D.1", "0.013089"},
                                                    {"initial.q_deg", "32"}});
  const auto e = extract_from_full(scene, 10, reduced::Method::Kinetostatic);
  ASSERT_TRUE(e.range);
  EXPECT_FALSE(e.samples.periodic);
  ASSERT_TRUE(e.dead_min && e.dead_max);
  // The blocked range: from the upper dead point to the lower one a turn later, ~2° wide.
  const double blocked = *e.dead_min + 2 * M_PI - *e.dead_max;
  EXPECT_GT(blocked, 0.5 * M_PI / 180);
  EXPECT_LT(blocked, 4.0 * M_PI / 180);
}

// The hard high-saddle leg is almost straight at the bottom of the stroke: at 10° the sweep
// comes back a turn later with m1 85.00 where it started at 84.57 (it went round on another
// assembly for part of the turn) and no dead point explains it, so the table is refused; at 1°
// it closes. validate's ladder takes such tables anyway (require_closed_turn off): its errors
// against the full model show what they cost.
TEST(BuildReduced, ATurnThatDoesNotCloseIsRefusedUnlessTheLadderAsks) {
  const auto scene = models::load_scene(RDYN_SCENES "/hard/high-saddle.yaml");
  try {
    extract_from_full(scene, 10, reduced::Method::Kinetostatic);
    ADD_FAILURE() << "a sweep that did not close its turn was accepted";
  } catch (const reduced::SweepNotClosed& e) {
    EXPECT_NE(std::string(e.what()).find("does not return to its start"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(extract_from_full(scene, 1, reduced::Method::Kinetostatic).samples.periodic);
  EXPECT_TRUE(extract_from_full(scene, 10, reduced::Method::Kinetostatic, false).samples.periodic);
}

// Rank loss between grid points: the isosceles slider-crank folds flat at 90° and 270° (crank
// driven), where its rod force has a pole. A 7.2° grid does not pass through either, nor does a
// declared slider range whose grid misses x = 0; the pole was then missed and the reduced model
// swung ±125 N for the full model's 1.7 N with exit 0. The extraction scans where the grid is
// poorly conditioned, checks each configuration of rank loss between grid points, and lists the
// poles; on grids through them it finds the same ones.
TEST(BuildReduced, PolesBetweenGridPointsAreFoundAndListed) {
  const auto crank = models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/iso-crank-driven.yaml");
  for (double grid : {7.2, 10.0}) {
    const auto e = extract_from_full(crank, grid, reduced::Method::Kinetostatic);
    ASSERT_EQ(e.samples.poles.size(), 1u) << grid;
    EXPECT_EQ(e.samples.poles[0].first, "rod_axial");
    ASSERT_EQ(e.samples.poles[0].second.size(), 2u) << grid;
    EXPECT_NEAR(e.samples.poles[0].second[0], M_PI / 2, 1e-8) << grid;
    EXPECT_NEAR(e.samples.poles[0].second[1], 3 * M_PI / 2, 1e-8) << grid;
  }
  auto slider = models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/iso-slider-crank.yaml");
  slider.independent_range = models::IndependentRange{-0.1, 0.1537};  // a grid of 0.00705 m: x = 0 between points
  const auto r = extract_from_full(slider, 10, reduced::Method::Kinetostatic);
  ASSERT_EQ(r.samples.poles.size(), 1u);
  ASSERT_EQ(r.samples.poles[0].second.size(), 1u);
  EXPECT_NEAR(r.samples.poles[0].second[0], 0.0, 1e-9);
  // A mechanism without rank loss is swept once, as before: no scan, no poles.
  const auto fourbar = extract_from_full(models::load_scene("fourbar"), 10, reduced::Method::Kinetostatic);
  EXPECT_TRUE(fourbar.samples.poles.empty());
  EXPECT_GT(fourbar.samples.min_conditioning, reduced::kScanBelowConditioning);
}

// m1 does not see everything a grid must resolve: a rotor geared 25:1 to the crank and 2 mm out
// of balance keeps m1 constant (its miss at 10° is rounding) while its weight's torque, in
// Q_cons, turns 25 times a turn. The default grid is refined on Q_cons until it resolves it too.
TEST(BuildReduced, AGeneralizedForceTheGridDoesNotResolveIsRefinedToo) {
  const auto press =
      models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/press-unbalanced-rotor.yaml");
  const auto coarse = extract_from_full(press, 10, reduced::Method::Kinetostatic);
  const int c = coarse.samples.column("m1");
  ASSERT_GE(c, 0);
  EXPECT_LT(reduced::calc_half_grid_miss(coarse.samples.columns[c]), 1e-6);
  const auto [column, miss] = calc_resolution_miss(coarse.samples);
  EXPECT_EQ(column, "Q_cons");
  EXPECT_GT(miss, 0.1);
  double grid = 0;
  const auto e = extract_resolving(press, 10, false, reduced::Method::Kinetostatic, grid);
  EXPECT_LT(grid, 10.0);
  EXPECT_LE(calc_resolution_miss(e.samples).second, kAutoRefineMiss);
}

// A range whose point force's points meet inside it (a cylinder-driven lift's cable, at a stroke
// of 0.3125 m of [0.30, 0.60], the start at 0.40) ends there on the start's side, named as such in
// the table (and read back); it was refused although the motion never gets there. The points meet
// between the 10° grid's points and on one of the 5° grid's: both end the same way.
TEST(BuildReduced, ARangeWhosePointForceMeetsInsideItEndsThere) {
  const auto scene =
      models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/loader-cable-meets.yaml");
  for (double grid : {10.0, 5.0}) {
    const auto e = extract_from_full(scene, grid, reduced::Method::Kinetostatic);
    ASSERT_TRUE(e.range);
    EXPECT_NEAR(e.range->min, 0.3125 + 1e-3 * (0.60 - 0.30), 1e-6) << grid;
    EXPECT_EQ(e.range->min_edge, reduced::kPointForceMeetingEdge);
    EXPECT_EQ(e.samples.min_edge, "point force meeting");
    EXPECT_EQ(e.range->max, 0.60);
    const auto file = std::filesystem::temp_directory_path() / ("rdyn_meet_" + std::to_string(::getpid()) + ".csv");
    reduced::write_samples_csv(file.string(), e.samples);
    EXPECT_EQ(reduced::read_samples_csv(file.string()).min_edge, "point force meeting");
    std::filesystem::remove(file);
  }
}

// A Q_cons that is rounding (no gravity, no spring) is not resolved: the grid is m1's to judge. A
// Q_cons of 1e-8 of m1's peak that turns 20 times a turn still is.
TEST(BuildReduced, AGeneralizedForceOfRoundingIsNotChased) {
  reduced::Samples s;
  s.periodic = true;
  s.names = {"m1", "Q_cons"};
  s.columns.resize(2);
  for (int i = 0; i < 36; ++i) {
    const double q = i * 10 * M_PI / 180;
    s.q.push_back(q);
    s.columns[0].push_back(2.0 + 0.1 * std::cos(q));
    s.columns[1].push_back(1e-17 * ((i * 7919) % 13 - 6));  // noise
  }
  auto [column, miss] = calc_resolution_miss(s);
  EXPECT_EQ(column, "m1");
  EXPECT_LT(miss, 1e-6);
  for (int i = 0; i < 36; ++i) s.columns[1][i] = 2e-8 * std::sin(20 * s.q[i]);
  std::tie(column, miss) = calc_resolution_miss(s);
  EXPECT_EQ(column, "Q_cons");
  EXPECT_GT(miss, 0.1);
}

// A flywheel geared 24:1 and out of balance, without gravity: m1 and Q_cons are resolved at 10°,
// its bearing's reaction line is not (the half table misses it by 2.0 of its peak); the default
// grid goes to 2.5°, where every line is resolved, and the reduced reaction agrees with the full
// model's at every grid point of the 2.5° table (at 10° it was 199 % off). The bicycle's knee line
// misses 0.11 at 10°, where the model is within 1e-3: it keeps 10°.
TEST(BuildReduced, AConstraintLineTheGridDoesNotResolveIsRefinedToo) {
  // With the internal lines of its joint outputs, as simulate extracts it.
  const auto scene = reduced::with_reaction_requests(
      models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/flywheel-24to1.yaml"));
  const auto coarse = extract_from_full(scene, 10, reduced::Method::Kinetostatic);
  EXPECT_LE(calc_resolution_miss(coarse.samples).second, kAutoRefineMiss);
  const auto [line, miss] = calc_line_resolution_miss(coarse.samples, scene);
  EXPECT_NE(line.find("R_flywheel_g"), std::string::npos) << line;
  EXPECT_GT(miss, 1.0);
  double grid = 0;
  const auto e = extract_resolving(scene, 10, false, reduced::Method::Kinetostatic, grid);
  EXPECT_EQ(grid, 2.5);
  EXPECT_LE(calc_line_resolution_miss(e.samples, scene).second, 1e-6);
  const auto bicycle = models::load_scene("bicycle");
  const auto b = extract_from_full(bicycle, 10, reduced::Method::Kinetostatic);
  const double knee = calc_line_resolution_miss(b.samples, bicycle).second;
  EXPECT_GT(knee, 0.05);
  EXPECT_LT(knee, kAutoRefineLineMiss);
  extract_resolving(bicycle, 10, false, reduced::Method::Kinetostatic, grid);
  EXPECT_EQ(grid, 10.0);
}

}  // namespace
}  // namespace rdyn::validate

namespace rdyn::validate {
namespace {

// A five-bar driven from the fast crank of a 1:2 gear comes back only after two turns: the
// one-turn sweep cannot close at any grid, and the message says so and names the way out (it
// blamed the grid). From the slow crank every joint repeats each turn, and the table closes.
TEST(BuildReduced, AMechanismGearedToRepeatEveryTwoTurnsIsToldAndTheSlowJointWorks) {
  auto scene = models::load_scene(RDYN_SOURCE_DIR "/tests/validate/scenes/fivebar-geared.yaml");
  try {
    extract_from_full(scene, 10, reduced::Method::Kinetostatic);
    ADD_FAILURE() << "a one-turn table of a two-turn mechanism was extracted";
  } catch (const reduced::SweepNotClosed& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("gear 'g' turns 'c2' 0.5 turn(s) per turn of 'c1'"), std::string::npos) << m;
    EXPECT_NE(m.find("repeats only every 2 turns of 'c1'"), std::string::npos) << m;
    EXPECT_EQ(m.find("finer grid"), std::string::npos) << m;
  }
  // A default grid is not halved for it: no grid closes the turn (five halvings took 1.4 s).
  testing::internal::CaptureStderr();
  double grid = 0.0;
  EXPECT_THROW(extract_resolving(scene, 10.0, false, reduced::Method::Kinetostatic, grid), reduced::SweepNotClosed);
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_EQ(said.find("extracting at"), std::string::npos) << said;
  scene.independent = "c2";
  scene.initial = {M_PI / 4, 5.0};
  const auto e = extract_from_full(scene, 5, reduced::Method::Kinetostatic);
  EXPECT_TRUE(e.samples.periodic);
  EXPECT_EQ(e.samples.q.size(), 72u);
}

// A default grid is halved while it does not resolve m1 (half-grid miss above kAutoRefineMiss);
// one the user gave is kept. The light-flywheel bicycle's 10° table misses 9.8e-3 (its q̈ was
// 1.1e-2 off): 5°, where it misses below the bound; the fourbar's (1.4e-4) stays at 10°.
TEST(BuildReduced, ADefaultGridIsRefinedUntilItResolvesM1AGivenOneIsKept) {
  const auto flywheel = models::load_scene(RDYN_SCENES "/hard/light-flywheel.yaml");
  double grid = 0;
  const auto e = extract_resolving(flywheel, 10, false, reduced::Method::Kinetostatic, grid);
  EXPECT_EQ(grid, 5.0);
  EXPECT_EQ(e.samples.q.size(), 72u);
  const int c = e.samples.column("m1");
  ASSERT_GE(c, 0);
  EXPECT_LE(reduced::calc_half_grid_miss(e.samples.columns[c]), kAutoRefineMiss);
  const auto coarse = extract_resolving(flywheel, 10, true, reduced::Method::Kinetostatic, grid);
  EXPECT_EQ(grid, 10.0);
  EXPECT_GT(reduced::calc_half_grid_miss(coarse.samples.columns[c]), kAutoRefineMiss);
  extract_resolving(models::load_scene("fourbar"), 10, false, reduced::Method::Kinetostatic, grid);
  EXPECT_EQ(grid, 10.0);
  // A default grid whose sweep does not close (a 1:20 gear turns its joint 200° per 10° step) is
  // halved too; a given one is refused as before.
  const auto geared = models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/fivebar-2to1.yaml",
                                         {models::parse_override("gears.pair.ratio=20")});
  EXPECT_THROW(extract_resolving(geared, 10, true, reduced::Method::Kinetostatic, grid), reduced::SweepNotClosed);
  EXPECT_NO_THROW(extract_resolving(geared, 10, false, reduced::Method::Kinetostatic, grid));
  EXPECT_LT(grid, 10.0);
}

}  // namespace
}  // namespace rdyn::validate
