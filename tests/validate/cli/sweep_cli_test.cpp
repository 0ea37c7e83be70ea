// `rdyn sweep` shards, `--resume` and `--merge` end to end through the binary (issue #28): the
// shards, run apart in one thread each and merged, are byte for byte the sweep run at once in
// two threads; a complete shard is skipped, a partial one run again; parts that are not one
// whole sweep are refused with status 2 and nothing written.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

struct SweepCli : ::testing::Test {
  fs::path dir;
  void SetUp() override {
    dir = fs::temp_directory_path() /
          ("rdyn_sweep_cli_" + std::to_string(::getpid()) + "_" +
           ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }

  // Six cases: three crank lengths (each a new mechanism) by two powers (one table each).
  test::RdynRun sweep(const std::vector<std::string>& more) {
    std::vector<std::string> args{"sweep",  "bicycle", "--vary", "bicycle_leg.crank_length_m=0.16:0.18:3",
                                  "--vary", "bicycle_leg.resistance.power_W=100:150:2"};
    args.insert(args.end(), more.begin(), more.end());
    return test::run_rdyn(args, dir);
  }
};

TEST_F(SweepCli, ShardsResumeAndMergeIntoTheOneProcessSweep) {
  const auto whole = sweep({"--threads", "2", "--out", "whole.csv"});
  ASSERT_EQ(whole.status, 0) << whole.err;
  EXPECT_NE(whole.err.find("rdyn: sweep shard 0/1: 6 cases in "), std::string::npos) << whole.err;
  EXPECT_NE(whole.err.find("2 threads, "), std::string::npos) << whole.err;
  EXPECT_NE(whole.err.find(" tables); wrote whole.csv"), std::string::npos) << whole.err;
  for (const char* shard : {"2/3", "0/3", "1/3"}) {
    const std::string name = std::string("part") + shard[0] + ".csv";
    const auto r = sweep({"--threads", "1", "--shard", shard, "--resume", "--out", name});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(std::string("sweep shard ") + shard + ": 2 cases in "), std::string::npos) << r.err;
  }
  const auto m = test::run_rdyn({"sweep", "--merge", "merged.csv", "part2.csv", "part0.csv", "part1.csv"}, dir);
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_NE(m.err.find("rdyn: sweep merge: 6 cases from 3 parts; wrote merged.csv"), std::string::npos) << m.err;
  const std::string merged = test::slurp(dir / "merged.csv");
  EXPECT_EQ(merged, test::slurp(dir / "whole.csv"));
  EXPECT_EQ(std::count(merged.begin(), merged.end(), '\n'), 8);  // metadata, header, six cases
  // The merge written over one of its own parts (here through another path) is refused, the part kept.
  const std::string part0 = test::slurp(dir / "part0.csv");
  const auto onto = test::run_rdyn({"sweep", "--merge", "./part0.csv", "part0.csv", "part1.csv", "part2.csv", "--force"},
                                   dir);
  EXPECT_EQ(onto.status, 2) << onto.err;
  EXPECT_NE(onto.err.find("is one of the parts (part0.csv)"), std::string::npos) << onto.err;
  EXPECT_EQ(test::slurp(dir / "part0.csv"), part0);

  // A complete shard is skipped: the file is not rewritten.
  const std::string part1 = test::slurp(dir / "part1.csv");
  const auto written = fs::last_write_time(dir / "part1.csv");
  const auto skip = sweep({"--threads", "1", "--shard", "1/3", "--resume", "--out", "part1.csv"});
  ASSERT_EQ(skip.status, 0) << skip.err;
  EXPECT_NE(skip.err.find("sweep shard 1/3: 2 cases already complete: skipped; wrote part1.csv"), std::string::npos)
      << skip.err;
  EXPECT_EQ(fs::last_write_time(dir / "part1.csv"), written);
  // A partial shard (its last row lost) is run again and completed.
  { std::ofstream(dir / "part1.csv", std::ios::binary) << part1.substr(0, part1.rfind('\n', part1.size() - 2) + 1); }
  const auto redo = sweep({"--threads", "1", "--shard", "1/3", "--resume", "--out", "part1.csv"});
  ASSERT_EQ(redo.status, 0) << redo.err;
  EXPECT_NE(redo.err.find("running it again: it is partial (case 3 is missing)"), std::string::npos) << redo.err;
  EXPECT_EQ(test::slurp(dir / "part1.csv"), part1);
  // Another sweep's file at --out is run again too (here: another cadence).
  const auto other = sweep({"--threads", "1", "--shard", "1/3", "--resume", "--cadence-hz", "1.2", "--out", "part1.csv"});
  ASSERT_EQ(other.status, 0) << other.err;
  EXPECT_NE(other.err.find("running it again: it holds another sweep"), std::string::npos) << other.err;
}

TEST_F(SweepCli, MergeRefusesPartsThatAreNotOneWholeSweep) {
  ASSERT_EQ(sweep({"--threads", "1", "--shard", "0/2", "--out", "a0.csv"}).status, 0);
  ASSERT_EQ(sweep({"--threads", "1", "--shard", "1/2", "--out", "a1.csv"}).status, 0);
  ASSERT_EQ(sweep({"--threads", "1", "--shard", "1/2", "--cadence-hz", "1.2", "--out", "b1.csv"}).status, 0);
  struct Bad {
    std::vector<std::string> parts;
    std::string message;
  };
  const std::vector<Bad> bad{
      {{"a0.csv", "b1.csv"}, "b1.csv:1: field 'sweep': the sweep (scene, axes, options) differs from a0.csv"},
      {{"a0.csv"}, "--merge: cases 3-6 are in no part given (of 6 cases in all)"},
      {{"a0.csv", "a1.csv", "a0.csv"}, "case 0 is also in a0.csv"},
      {{"a0.csv", "nothing.csv"}, "nothing.csv: field 'file': cannot read: no such file"},
  };
  for (const auto& b : bad) {
    std::vector<std::string> args{"sweep", "--merge", "m.csv"};
    args.insert(args.end(), b.parts.begin(), b.parts.end());
    const auto r = test::run_rdyn(args, dir);
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_NE(r.err.find(b.message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "m.csv"));
  }
  // A file rdyn did not write is not replaced by a merge.
  { std::ofstream(dir / "notes.csv") << "mine\n"; }
  const auto foreign = test::run_rdyn({"sweep", "--merge", "notes.csv", "a0.csv", "a1.csv"}, dir);
  EXPECT_EQ(foreign.status, 2) << foreign.err;
  EXPECT_EQ(test::slurp(dir / "notes.csv"), "mine\n");
  // --merge takes parts, not sweep options; a sweep takes one scene.
  EXPECT_EQ(test::run_rdyn({"sweep", "--merge", "m.csv", "a0.csv", "--shard", "0/2"}, dir).status, 2);
  const auto two = sweep({"--out", "x.csv", "extra.yaml"});
  EXPECT_EQ(two.status, 2) << two.err;
  EXPECT_NE(two.err.find("give one scene"), std::string::npos) << two.err;
  EXPECT_FALSE(fs::exists(dir / "x.csv"));
}

// --drive-cadence-hz through the binary: the drive's columns in place of the calibration's
// (their values: tests/validate/analysis/sweep_test.cpp, tests/python), and the option refused
// (exit 2, nothing written) when zero, out of range or beside a calibration option.
TEST_F(SweepCli, DriveCadenceGivesTheDrivesColumns) {
  const auto r = sweep({"--drive-cadence-hz", "1", "--out", "drive.csv"});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = test::slurp(dir / "drive.csv");
  EXPECT_NE(csv.find("\ncase,bicycle_leg.crank_length_m,bicycle_leg.resistance.power_W,status,drive_rms_Nm,"
                     "drive_peak_Nm,drive_mean_Nm,mean_power_w,peak_power_w,peak_knee_force_N,error\n"),
            std::string::npos)
      << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 8);  // metadata, header, six cases
  EXPECT_EQ(csv.find(",error,"), std::string::npos) << csv;
  for (const auto& more : std::vector<std::vector<std::string>>{{"--drive-cadence-hz", "0"},
                                                                 {"--drive-cadence-hz", "2000"},
                                                                 {"--drive-cadence-hz", "nan"},
                                                                 {"--drive-cadence-hz", "1", "--cadence-hz", "1"},
                                                                 {"--drive-cadence-hz", "1", "--power-w", "100"}}) {
    std::vector<std::string> args = more;
    args.insert(args.end(), {"--out", "bad.csv"});
    const auto b = sweep(args);
    EXPECT_EQ(b.status, 2) << more[1] << " " << b.err;
    EXPECT_FALSE(fs::exists(dir / "bad.csv")) << more[1];
  }
}

// --peak through the binary: its columns in the header, shards with --peak merged byte for byte
// into the one-process sweep, a part with other --peak columns refused by --merge, and an
// unknown or unrequested column refused before any case runs (exit 2, naming --peak and the
// columns there are, nothing written). Values: tests/validate/analysis/sweep_peaks_test.cpp.
TEST_F(SweepCli, PeakColumnsShardMergeAndRefuse) {
  const std::vector<std::string> args{"sweep", "bicycle", "--vary", "bicycle_leg.crank_length_m=0.16:0.18:2",
                                      "--peak", "F_knee", "--peak", "qdot"};
  auto run = [&](std::vector<std::string> more) {
    std::vector<std::string> a = args;
    a.insert(a.end(), more.begin(), more.end());
    return test::run_rdyn(a, dir);
  };
  const auto whole = run({"--threads", "2", "--out", "whole.csv"});
  ASSERT_EQ(whole.status, 0) << whole.err;
  const std::string csv = test::slurp(dir / "whole.csv");
  EXPECT_NE(csv.find(",speed_fluctuation,peak_F_knee,peak_qdot,error\n"), std::string::npos) << csv;
  for (const char* shard : {"0/2", "1/2"})
    ASSERT_EQ(run({"--threads", "1", "--shard", shard, "--out", std::string("p") + shard[0] + ".csv"}).status, 0);
  const auto m = test::run_rdyn({"sweep", "--merge", "merged.csv", "p1.csv", "p0.csv"}, dir);
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_EQ(test::slurp(dir / "merged.csv"), csv);
  // The same shard without --peak is another sweep.
  ASSERT_EQ(test::run_rdyn({"sweep", "bicycle", "--vary", "bicycle_leg.crank_length_m=0.16:0.18:2", "--threads", "1",
                            "--shard", "1/2", "--out", "plain1.csv"},
                           dir)
                .status,
            0);
  const auto mixed = test::run_rdyn({"sweep", "--merge", "mixed.csv", "p0.csv", "plain1.csv"}, dir);
  EXPECT_EQ(mixed.status, 2) << mixed.err;
  EXPECT_NE(mixed.err.find("plain1.csv:1: field 'sweep'"), std::string::npos) << mixed.err;
  EXPECT_FALSE(fs::exists(dir / "mixed.csv"));
  for (const char* column : {"F_hip", "R_knee_x"}) {
    const auto bad = run({"--peak", column, "--out", "bad.csv"});
    EXPECT_EQ(bad.status, 2) << bad.err;
    EXPECT_NE(bad.err.find("field '--peak'"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find("this sweep's columns: q, qdot, qddot, energy, work, F_knee"), std::string::npos) << bad.err;
    EXPECT_FALSE(fs::exists(dir / "bad.csv"));
  }
}

}  // namespace
}  // namespace rdyn::validate
