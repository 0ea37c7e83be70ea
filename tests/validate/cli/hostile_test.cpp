// The hostile-input suite (issue #9): every subcommand against what a careless or hostile
// user can type. Each case asserts the exit status, the message, and what is left on disk:
// nothing deleted or changed that rdyn did not write, no temporary left behind, no shell run
// (a PWNED file would appear), no NaN in an output, no hang (a time limit per case).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <tuple>

#include "tests/validate/run_rdyn.hpp"

namespace {

namespace fs = std::filesystem;
using rdyn::test::RdynRun;
using rdyn::test::run_rdyn;
using rdyn::test::RunLimits;
using rdyn::test::slurp;

struct Case {
  std::string name;               // test name (letters, digits, _)
  std::vector<std::string> args;  // after `rdyn`; run in a fresh folder
  int status = 2;                 // expected exit status
  std::string message;            // expected in standard error
  std::map<std::string, std::string> files{};     // written before the run; must be intact after
  std::function<void(const fs::path&)> setup{};   // more set-up (FIFOs, links, folders)
  std::string out{};                              // must not exist after a failure
  RunLimits limits{};
  std::function<void(const fs::path&, const RdynRun&)> check{};  // more assertions
};

// Test names only, instead of gtest's byte dump of the parameter.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::string scene_text(const std::string& name) { return slurp(fs::path(RDYN_SCENES) / (name + ".yaml")); }

// `text` with `from` replaced by `to` (the case fails loudly if `from` is missing).
std::string edit(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) return "# edit target missing: " + from + "\n";
  return text.replace(at, from.size(), to);
}

std::vector<Case> all_cases();

class Hostile : public ::testing::TestWithParam<Case> {};

TEST_P(Hostile, ExitStatusMessageAndDisk) {
  const Case& c = GetParam();
  const fs::path dir = fs::temp_directory_path() / ("rdyn_hostile_" + std::to_string(getpid()) + "_" + c.name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const auto& [name, text] : c.files) {
    fs::create_directories((dir / name).parent_path());
    std::ofstream(dir / name, std::ios::binary) << text;
  }
  if (c.setup) c.setup(dir);
  const RdynRun r = run_rdyn(c.args, dir, c.limits);

  EXPECT_FALSE(r.timed_out) << "hung";
  EXPECT_EQ(r.status, c.status) << r.err;
  EXPECT_NE(r.err.find(c.message), std::string::npos) << "expected «" << c.message << "» in: " << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  for (const auto& [name, text] : c.files) EXPECT_EQ(slurp(dir / name), text) << name << " was changed";
  if (r.status != 0 && !c.out.empty()) {
    EXPECT_FALSE(fs::exists(fs::symlink_status(dir / c.out))) << c.out << " left after a failure";
  }
  const std::regex non_finite("(^|,)-?(nan|inf)(,|$)", std::regex::icase | std::regex::multiline);
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    EXPECT_EQ(name.find("rdyn-tmp"), std::string::npos) << "temporary left: " << it->path();
    EXPECT_NE(name, "PWNED") << "a shell ran user text";
    std::error_code fe;
    const bool input = c.files.count(fs::relative(it->path(), dir, fe).string()) > 0;  // the case's own files
    if (!input && it->is_regular_file(fe) && it->path().extension() == ".csv" && it->file_size(fe) < (1u << 24)) {
      EXPECT_FALSE(std::regex_search(slurp(it->path()), non_finite)) << "non-finite value in " << it->path();
    }
  }
  EXPECT_FALSE(fs::exists("PWNED"));
  if (c.check) c.check(dir, r);
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Cases, Hostile, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// --- the cases ------------------------------------------------------------------------

// Every numeric option of every subcommand against values that are not numbers or are out
// of range: exit 2, the option named, nothing written.
void bad_numbers(std::vector<Case>& cs) {
  struct Opt {
    std::string tag;
    std::vector<std::string> prefix;  // the command up to the option
    std::string option;
    std::vector<std::string> suffix;
    std::vector<std::string> bad;
  };
  const std::vector<std::string> common{"nan", "inf", "-1", "1e300", "abc", "-inf"};
  const std::vector<Opt> opts{
      {"sim_duration", {"simulate", "fourbar"}, "--duration", {"--out", "o"}, {"nan", "inf", "-1", "0", "1e300", "abc"}},
      {"sim_dtout", {"simulate", "fourbar"}, "--dt-out", {"--out", "o"}, {"nan", "inf", "-1", "0", "1e-12", "abc"}},
      {"sim_tol", {"simulate", "fourbar"}, "--tolerance", {"--out", "o"}, {"nan", "inf", "-1", "0", "2", "1e-300"}},
      {"sim_redtol", {"simulate", "fourbar", "--model", "reduced"}, "--reduced-tolerance", {"--out", "o"},
       {"nan", "inf", "-1", "0", "2", "1e-300"}},
      {"sim_grid", {"simulate", "fourbar", "--model", "reduced"}, "--grid-deg", {"--out", "o"},
       {"nan", "inf", "-10", "0", "1e-6", "7"}},
      {"sim_fixed", {"simulate", "fourbar", "--model", "reduced", "--reduced-integrator", "rk4-fixed"}, "--fixed-step",
       {"--out", "o"}, {"nan", "inf", "-1", "0", "1e-12", "10"}},
      {"ext_grid", {"extract", "fourbar"}, "--grid-deg", {"--out", "t.csv"}, {"nan", "inf", "-10", "0", "1e-6", "7"}},
      {"cal_cadence", {"calibrate", "bicycle"}, "--cadence-hz", {}, {"nan", "inf", "-1", "0", "1e9", "abc"}},
      {"cal_power", {"calibrate", "bicycle"}, "--power-w", {}, {"nan", "inf", "-1", "0", "1e300", "abc"}},
      {"cal_grid", {"calibrate", "bicycle"}, "--grid-deg", {}, {"nan", "-1", "0", "1e-6", "7", "abc"}},
      {"sweep_threads", {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2"}, "--threads",
       {"--out", "s.csv"}, {"-1", "2000", "1e9", "abc", "nan", "99999999999"}},
      {"sweep_grid", {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2"}, "--grid-deg",
       {"--out", "s.csv"}, {"nan", "-1", "0", "1e-6", "7", "inf"}},
      {"sweep_cadence", {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2"}, "--cadence-hz",
       {"--out", "s.csv"}, {"nan", "-1", "1e9", "inf", "abc", "-inf"}},
      {"sweep_power", {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2"}, "--power-w",
       {"--out", "s.csv"}, {"nan", "-1", "1e300", "inf", "abc", "-inf"}},
  };
  (void)common;
  for (const auto& o : opts)
    for (size_t k = 0; k < o.bad.size(); ++k) {
      Case c;
      c.name = o.tag + "_bad" + std::to_string(k);
      c.args = o.prefix;
      c.args.push_back(o.option);
      c.args.push_back(o.bad[k]);
      c.args.insert(c.args.end(), o.suffix.begin(), o.suffix.end());
      c.message = o.option;
      c.out = o.suffix.size() == 2 ? o.suffix[1] : "";
      cs.push_back(c);
    }
  // A duration below the shortest output interval names --duration (it blamed the --dt-out never given,
  // with the empty range [1e-06, 1e-300]).
  cs.push_back({"sim_duration_tiny", {"simulate", "fourbar", "--duration", "1e-300", "--out", "o"}, 2,
                "--duration: must be a finite number in [1e-06", {}, nullptr, "o"});
  // Sweep ranges and shards.
  const std::vector<std::pair<std::string, std::string>> shards{
      {"x", "--shard"}, {"1/1", "--shard"}, {"-1/2", "--shard"}, {"0/0", "--shard"}, {"0/2x", "--shard"},
      {"3/2", "--shard"}, {"0/99999999999", "--shard"}};
  for (size_t k = 0; k < shards.size(); ++k)
    cs.push_back({"sweep_shard_bad" + std::to_string(k),
                  {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2", "--shard", shards[k].first,
                   "--out", "s.csv"},
                  2, shards[k].second, {}, nullptr, "s.csv"});
  const std::vector<std::string> axes{"x=1:2", "x=1:2:0", "=1:2:3", "x=1:nan:3", "x=1:2:1e9", "x=1:2:3:4",
                                      "bicycle_leg.hip_torque_Nm=1:2:-3", "no.such.key=1:2:2",
                                      "bicycle_leg.subject.height_m=-1:2:2"};
  for (size_t k = 0; k < axes.size(); ++k)
    cs.push_back({"sweep_vary_bad" + std::to_string(k),
                  {"sweep", "bicycle", "--vary", axes[k], "--out", "s.csv"}, 2, "", {}, nullptr, "s.csv"});
  // Too many cases in all.
  cs.push_back({"sweep_too_many_cases",
                {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:10000", "--vary",
                 "bicycle_leg.crank_length_m=0.16:0.18:10000", "--out", "s.csv"},
                2, "cases", {}, nullptr, "s.csv"});
}

// Outputs: nothing of the user's is deleted, truncated or replaced; special files are
// written through or refused; user text never reaches a shell.
void outputs(std::vector<Case>& cs) {
  const std::string user_file = "a scene the user wrote\n";
  // Folders that hold the user's files.
  for (const std::string cmd : {"simulate", "validate"}) {
    Case c;
    c.name = cmd + "_refuses_foreign_folder";
    c.args = {cmd, "fourbar", "--out", "proj"};
    if (cmd == "simulate") c.args.insert(c.args.end(), {"--duration", "0.1"});
    c.files = {{"proj/scene.yaml", user_file}, {"proj/sub/notes.txt", "notes\n"}};
    c.message = "rdyn did not write";
    cs.push_back(c);
  }
  cs.push_back({"simulate_force_keeps_foreign_files",
                {"simulate", "fourbar", "--duration", "0.1", "--out", "proj", "--force"},
                0, "", {{"proj/scene.yaml", user_file}}, nullptr, "", {},
                [](const fs::path& d, const RdynRun&) {
                  EXPECT_TRUE(fs::exists(d / "proj/timeseries.csv"));
                  EXPECT_TRUE(fs::exists(d / "proj/.rdyn-output"));
                }});
  cs.push_back({"simulate_replaces_its_own_output",
                {"simulate", "fourbar", "--duration", "0.1", "--out", "o"},
                0, "", {}, [](const fs::path& d) {
                  fs::create_directories(d / "o");
                  std::ofstream(d / "o/.rdyn-output") << "rdyn output v1\nold.csv\n";
                  std::ofstream(d / "o/old.csv") << "t\n";
                }, "", {},
                [](const fs::path& d, const RdynRun&) {
                  EXPECT_TRUE(fs::exists(d / "o/timeseries.csv"));
                  EXPECT_FALSE(fs::exists(d / "o/old.csv"));  // rdyn's own earlier file
                }});
  cs.push_back({"simulate_refuses_rdyn_output_with_extra_file",
                {"simulate", "fourbar", "--duration", "0.1", "--out", "o"},
                2, "mine.txt", {{"o/mine.txt", "mine\n"}}, [](const fs::path& d) {
                  std::ofstream(d / "o/.rdyn-output") << "rdyn output v1\ntimeseries.csv\n";
                }});
  cs.push_back({"simulate_out_is_a_file", {"simulate", "fourbar", "--duration", "0.1", "--out", "f"}, 2,
                "not a folder", {{"f", user_file}}});
  cs.push_back({"simulate_out_parent_is_a_file",
                {"simulate", "fourbar", "--duration", "0.1", "--out", "f/sub"}, 2, "f/sub", {{"f", user_file}}});
  cs.push_back({"simulate_out_root", {"simulate", "fourbar", "--duration", "0.1", "--out", "/"}, 2, "/"});
  cs.push_back({"simulate_out_dot", {"simulate", "fourbar", "--duration", "0.1", "--out", "."}, 2, "",
                {{"keep.txt", user_file}}});
  cs.push_back({"simulate_out_empty", {"simulate", "fourbar", "--duration", "0.1", "--out", ""}, 2, "--out"});
  cs.push_back({"simulate_creates_parents", {"simulate", "fourbar", "--duration", "0.1", "--out", "a/b/c"}, 0, "",
                {}, nullptr, "", {}, [](const fs::path& d, const RdynRun&) {
                  EXPECT_TRUE(fs::exists(d / "a/b/c/timeseries.csv"));
                }});
  cs.push_back({"simulate_failure_removes_created_parents",
                {"simulate", "/no/such.yaml", "--out", "a/b/c"}, 2, "/no/such.yaml", {}, nullptr, "a"});
  cs.push_back({"simulate_follows_symlink_to_folder",
                {"simulate", "fourbar", "--duration", "0.1", "--out", "link"}, 0, "", {},
                [](const fs::path& d) {
                  fs::create_directories(d / "real");
                  fs::create_directory_symlink("real", d / "link");
                },
                "", {}, [](const fs::path& d, const RdynRun&) {
                  EXPECT_TRUE(fs::is_symlink(d / "link"));
                  EXPECT_TRUE(fs::exists(d / "real/timeseries.csv"));
                }});
  // Shell metacharacters and newlines in output names are plain characters.
  for (const auto& [tag, name] : std::vector<std::pair<std::string, std::string>>{
           {"quote", "o/x';touch PWNED;'"}, {"dollar", "o/$(touch PWNED)"}, {"backtick", "o/`touch PWNED`"},
           {"newline", "o/a\nb"}, {"semicolon", "o/a;touch PWNED"}}) {
    cs.push_back({"simulate_out_" + tag, {"simulate", "fourbar", "--duration", "0.1", "--out", name}, 0, ""});
    cs.push_back({"extract_out_" + tag, {"extract", "fourbar", "--out", name + ".csv"}, 0, ""});
  }
  // Single-file outputs.
  for (const auto& [cmd, args] : std::vector<std::pair<std::string, std::vector<std::string>>>{
           {"extract", {"extract", "fourbar", "--out", "t.csv"}},
           {"sweep", {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:60:1", "--out", "t.csv"}},
           {"calibrate", {"calibrate", "bicycle", "--write-scene", "t.csv"}}}) {
    cs.push_back({cmd + "_refuses_foreign_file", args, 2, "not written by rdyn", {{"t.csv", user_file}}});
    auto forced = args;
    forced.push_back("--force");
    if (cmd == "extract")
      cs.push_back({cmd + "_force_replaces_file", forced, 0, "", {}, [](const fs::path& d) {
                      std::ofstream(d / "t.csv") << "old\n";
                    }, "", {}, [](const fs::path& d, const RdynRun&) {
                      EXPECT_EQ(slurp(d / "t.csv").rfind("old", 0), std::string::npos);
                    }});
    cs.push_back({cmd + "_out_is_folder", args, 2, "folder", {{"t.csv/keep", user_file}}});
    cs.push_back({cmd + "_fifo_without_reader", args, 2, "FIFO", {}, [](const fs::path& d) {
                    mkfifo((d / "t.csv").c_str(), 0644);
                  }});
  }
  cs.push_back({"extract_rerun_replaces_own_table", {"extract", "fourbar", "--out", "t.csv"}, 0, "", {},
                [](const fs::path& d) {
                  const RdynRun r = run_rdyn({"extract", "fourbar", "--grid-deg", "30", "--out", "t.csv"}, d);
                  EXPECT_EQ(r.status, 0) << r.err;
                }});
  cs.push_back({"extract_to_dev_null", {"extract", "fourbar", "--out", "/dev/null"}, 0, ""});
  // Standard output redirected to a file (as the test runs rdyn): written through, appended.
  for (const std::string name : {"/dev/stdout", "/dev/fd/1", "/proc/self/fd/1"})
    cs.push_back({"extract_to_" + std::string(name == "/dev/stdout" ? "stdout" : name == "/dev/fd/1" ? "dev_fd" : "proc_fd"),
                  {"extract", "fourbar", "--out", name}, 0, "", {}, nullptr, "", {},
                  [](const fs::path&, const RdynRun& r) { EXPECT_EQ(r.out.rfind("# rdyn-table v1", 0), 0u) << r.out; }});
  cs.push_back({"extract_to_dev_full", {"extract", "fourbar", "--out", "/dev/full"}, 2, "No space left"});
  // A kernel file is not a stream (written through as root, /proc/sys/… changed a setting).
  cs.push_back({"extract_to_proc_comm", {"extract", "fourbar", "--out", "/proc/self/comm"}, 2, "kernel or device file"});
  cs.push_back({"extract_follows_symlink_to_file", {"extract", "fourbar", "--out", "link.csv"}, 0, "", {},
                [](const fs::path& d) { fs::create_symlink("real.csv", d / "link.csv"); }, "", {},
                [](const fs::path& d, const RdynRun&) {
                  EXPECT_TRUE(fs::is_symlink(d / "link.csv"));
                  EXPECT_GT(fs::file_size(d / "real.csv"), 100u);
                }});
  cs.push_back({"extract_symlink_to_foreign_file_refused", {"extract", "fourbar", "--out", "link.csv"}, 2,
                "not written by rdyn", {{"real.csv", user_file}},
                [](const fs::path& d) { fs::create_symlink("real.csv", d / "link.csv"); }});
  cs.push_back({"extract_symlink_loop", {"extract", "fourbar", "--out", "a.csv"}, 2, "symbolic link", {},
                [](const fs::path& d) {
                  fs::create_symlink("b.csv", d / "a.csv");
                  fs::create_symlink("a.csv", d / "b.csv");
                }});
  // A full disk (a file-size limit) fails cleanly with the system's reason and leaves nothing.
  {
    Case c{"simulate_full_disk", {"simulate", "fourbar", "--duration", "1", "--out", "o"}, 2, "File too large"};
    c.out = "o";
    c.limits.file_size_limit = 4096;
    cs.push_back(c);
    Case e{"extract_full_disk", {"extract", "fourbar", "--grid-deg", "1", "--out", "t.csv"}, 2, "File too large"};
    e.out = "t.csv";
    e.limits.file_size_limit = 4096;
    cs.push_back(e);
  }
  // A bad operating point is refused before any work: validation runs its calibration last
  // (about a minute and a half in), but the load it names is checked first. The time limit makes
  // the late refusal this replaced (68 s) a failure.
  {
    Case c{"validate_calibrate_load_unknown_refused_first",
           {"validate", "bicycle", "--set", "validation.calibrate.load=nope", "--out", "o"}, 2,
           "--set validation.calibrate.load"};
    c.out = "o";
    c.limits.time_limit_s = 10.0;
    cs.push_back(c);
  }
  // Interrupted runs leave nothing (the signal's own status: 128 + signal).
  for (const auto& [tag, sig] : std::vector<std::pair<std::string, int>>{{"int", SIGINT}, {"term", SIGTERM}, {"hup", SIGHUP}}) {
    Case c{"simulate_interrupted_" + tag, {"simulate", "bicycle", "--duration", "500", "--out", "x/o"}, 128 + sig, ""};
    c.out = "x";
    c.limits.signal_after_ms = 1500;
    c.limits.signal = sig;
    cs.push_back(c);
  }
  // An interrupted run removes only its own temporary and the parent folders it created while
  // they are empty: another run's results and the user's files put there meanwhile stay.
  {
    Case c{"interrupted_run_keeps_others_files_in_created_parent",
           {"simulate", "bicycle", "--duration", "500", "--out", "shared/o1"}, 128 + SIGINT, ""};
    c.limits.signal_after_ms = 2500;
    c.limits.during_after_ms = 800;  // once the first run has created shared/
    c.limits.during = [](const fs::path& d) {
      const RdynRun other = run_rdyn({"simulate", "fourbar", "--duration", "0.1", "--out", "shared/o2"}, d);
      EXPECT_EQ(other.status, 0) << other.err;
      std::ofstream(d / "shared/readme.txt") << "mine\n";
    };
    c.check = [](const fs::path& d, const RdynRun&) {
      EXPECT_EQ(slurp(d / "shared/readme.txt"), "mine\n");
      EXPECT_TRUE(fs::exists(d / "shared/o2/timeseries.csv"));
      EXPECT_FALSE(fs::exists(d / "shared/o1"));
    };
    cs.push_back(c);
  }
  // Suites: names that would escape or collide are refused before any work.
  const std::string fb = scene_text("fourbar");
  cs.push_back({"suite_collision", {"validate", "--suite", "s", "--out", "o"}, 2, "same name",
                {{"s/a.yaml", fb}, {"s/a.yml", fb}}, nullptr, "o"});
  for (const auto& [tag, file] : std::vector<std::pair<std::string, std::string>>{
           {"dots", "s/...yaml"}, {"dash", "s/-x.yaml"}, {"space", "s/a b.yaml"}, {"quote", "s/a'b.yaml"},
           {"html", "s/<b>.yaml"}, {"leading_dot", "s/.hidden.yaml"}}) {
    cs.push_back({"suite_name_" + tag, {"validate", "--suite", "s", "--out", "o"}, 2, "plain name",
                  {{file, fb}}, nullptr, "o"});
  }
  cs.push_back({"suite_not_a_folder", {"validate", "--suite", "nowhere", "--out", "o"}, 2, "nowhere", {}, nullptr, "o"});
  cs.push_back({"suite_empty", {"validate", "--suite", "s", "--out", "o"}, 2, "no .yaml", {{"s/readme.txt", "x"}},
                nullptr, "o"});
  cs.push_back({"validate_scene_and_suite", {"validate", "fourbar", "--suite", "s", "--out", "o"}, 2, "not both"});
  cs.push_back({"validate_neither", {"validate", "--out", "o"}, 2, "give a scene"});
  cs.push_back({"validate_quick_and_thorough", {"validate", "fourbar", "--quick", "--thorough", "--out", "o"}, 2,
                "--quick"});
}

// Scenes: values, names, structure and YAML tricks, through every subcommand that reads a
// scene: exit 2 with the field named, nothing written.
void scenes(std::vector<Case>& cs) {
  const std::string fb = scene_text("fourbar");
  struct Bad {
    std::string tag, text, field;  // field: expected in the message
  };
  const std::string crank = "{name: crank,   mass_kg: 0.50, com_m: [0.04, 0], inertia_kgm2: 2.667e-4, points: {B: [0.08, 0]}}";
  auto crank_with = [&](const std::string& from, const std::string& to) { return edit(fb, crank, edit(crank, from, to)); };
  const std::vector<Bad> bad{
      {"mass_nan", crank_with("mass_kg: 0.50", "mass_kg: .nan"), "mass_kg"},
      {"mass_negative", crank_with("mass_kg: 0.50", "mass_kg: -0.5"), "mass_kg"},
      {"mass_zero", crank_with("mass_kg: 0.50", "mass_kg: 0"), "mass_kg"},
      {"mass_huge", crank_with("mass_kg: 0.50", "mass_kg: 1e300"), "mass_kg"},
      {"mass_text", crank_with("mass_kg: 0.50", "mass_kg: heavy"), "mass_kg"},
      {"mass_list", crank_with("mass_kg: 0.50", "mass_kg: [1, 2]"), "mass_kg"},
      {"inertia_zero", crank_with("inertia_kgm2: 2.667e-4", "inertia_kgm2: 0"), "inertia_kgm2"},
      {"inertia_inf", crank_with("inertia_kgm2: 2.667e-4", "inertia_kgm2: .inf"), "inertia_kgm2"},
      {"point_huge", crank_with("B: [0.08, 0]", "B: [1e9, 0]"), "B"},
      {"point_nan", crank_with("B: [0.08, 0]", "B: [.nan, 0]"), "B"},
      {"point_short", crank_with("B: [0.08, 0]", "B: [0.08]"), "B"},
      {"com_nan", crank_with("com_m: [0.04, 0]", "com_m: [0.04, .nan]"), "com_m"},
      {"duplicate_key", crank_with("mass_kg: 0.50,", "mass_kg: 0.50, mass_kg: 0.6,"), "duplicate key"},
      {"duplicate_top_key", fb + "gravity: {enabled: false}\n", "duplicate key"},
      {"name_comma", edit(fb, "name: fourbar", "name: \"four,bar\""), "not a valid name"},
      {"name_newline", edit(fb, "name: fourbar", "name: \"four\\nbar\""), "not a valid name"},
      {"name_html", edit(fb, "name: fourbar", "name: \"<script>x</script>\""), "not a valid name"},
      {"name_quote", edit(fb, "name: fourbar", "name: \"a'b\""), "not a valid name"},
      {"name_slash", edit(fb, "name: fourbar", "name: \"../../etc\""), "not a valid name"},
      {"name_space", edit(fb, "name: fourbar", "name: \"four bar\""), "not a valid name"},
      {"name_long", edit(fb, "name: fourbar", "name: " + std::string(100, 'x')), "not a valid name"},
      {"force_name_comma", edit(fb, "name: rocker_axial", "name: \"a,b\""), "not a valid name"},
      {"body_duplicate", edit(fb, "{name: coupler, mass_kg", "{name: crank, mass_kg"), "crank"},
      {"gear_self", edit(fb, "independent: crank", "gears: [{name: g, driver: crank, driven: crank, ratio: 2}]\nindependent: crank"), "driven"},
      {"gear_ratio_zero", edit(fb, "independent: crank", "gears: [{name: g, driver: crank, driven: rocker, ratio: 0}]\nindependent: crank"), "ratio"},
      {"motor_opposite_sign", edit(fb, "loads:\n", "loads:\n  - {type: motor, name: m, joint: crank, stall_torque_Nm: 1, no_load_speed_rad_s: -5}\n"), "sign"},
      {"motor_zero_speed", edit(fb, "loads:\n", "loads:\n  - {type: motor, name: m, joint: crank, stall_torque_Nm: 1, no_load_speed_rad_s: 0}\n"), "no_load_speed"},
      {"resistance_huge", edit(fb, "coefficient: 1.0e-3", "coefficient: 1.0e12"), "coefficient"},
      {"resistance_negative", edit(fb, "coefficient: 1.0e-3", "coefficient: -1"), "coefficient"},
      {"resistance_law", edit(fb, "law: viscous", "law: magic"), "law"},
      {"tolerance_zero", edit(fb, "tolerance: 1.0e-9", "tolerance: 0"), "tolerance"},
      {"interval_tiny", edit(fb, "output_interval_s: 0.002", "output_interval_s: 1e-12"), "output_interval_s"},
      {"duration_huge", edit(fb, "duration_s: 3", "duration_s: 1e9"), "duration_s"},
      {"duration_negative", edit(fb, "duration_s: 3", "duration_s: -3"), "duration_s"},
      {"qdot_nan", edit(fb, "qdot: 8.0", "qdot: .nan"), "qdot"},
      {"qdot_huge", edit(fb, "qdot: 8.0", "qdot: 1e30"), "qdot"},
      {"gravity_inf", edit(fb, "g_m_s2: [0, -9.81]", "g_m_s2: [0, .inf]"), "g_m_s2"},
      {"unknown_key", fb + "bogus: 1\n", "bogus"},
      {"unknown_joint_ref", edit(fb, "independent: crank", "independent: nosuch"), "independent"},
      {"direction_zero", edit(fb, "direction: C", "direction: [0, 0]"), "direction"},
      {"joint_type", edit(fb, "type: revolute, parent: crank", "type: spherical, parent: crank"), "type"},
      {"truncated", fb.substr(0, fb.size() / 2) + "\n  - {name: [", ""},
      {"binary", std::string("\x00\x01\xff\xfe garbage", 12), ""},
      {"empty", "", ""},
      {"not_a_map", "- 1\n- 2\n", ""},
      {"deep_nesting", std::string(200, '[') + std::string(200, ']') + "\n", "nest"},
      {"billion_laughs",
       "a: &a [x, x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
       "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b, *b]\nd: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
       "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d, *d]\nf: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e, *e]\n",
       ""},
      {"too_large", fb + "# " + std::string(1 << 21, 'x') + "\n", "too large"},
      {"loop_cannot_close", edit(fb, "ground_points: {A: [0.0, 0.0], D: [0.30, 0.0]}", "ground_points: {A: [0.0, 0.0], D: [3.0, 0.0]}"), "C"},
      // Profiled drive loads (models/load_profile.hpp): every number and the table's order.
      {"profile_nan", edit(fb, "loads:\n", "loads:\n  - {type: joint_torque, name: p, joint: crank, profile: {of: rocker, fourier: {a0: .nan}}}\n"), "profile.fourier.a0"},
      {"profile_unknown_joint", edit(fb, "loads:\n", "loads:\n  - {type: joint_torque, name: p, joint: crank, profile: {of: knee, fourier: {a0: 1}}}\n"), "profile.of"},
      {"profile_too_many", edit(fb, "loads:\n", "loads:\n  - {type: joint_torque, name: p, joint: crank, profile: {of: crank, fourier: {a: [" + [] { std::string a; for (int i = 0; i < 65; ++i) a += (i ? ", 1" : "1"); return a; }() + "]}}}\n"), "profile.fourier.a"},
      {"profile_unordered", edit(fb, "loads:\n", "loads:\n  - {type: joint_torque, name: p, joint: crank, profile: {of: crank, table_deg: [[0, 1], [180, 2], [90, 3]]}}\n"), "table_deg[2][0]"},
      {"profile_over_a_turn", edit(fb, "loads:\n", "loads:\n  - {type: joint_torque, name: p, joint: crank, profile: {of: crank, table_deg: [[0, 1], [180, 2], [360, 3]]}}\n"), "table_deg[2][0]"},
      {"profile_amplitude_huge", edit(fb, "loads:\n", "loads:\n  - {type: joint_torque, name: p, joint: crank, torque_Nm: 1e5, profile: {of: crank, fourier: {a0: 20}}}\n"), "torque_Nm"},
  };
  for (const auto& b : bad) {
    cs.push_back({"scene_" + b.tag + "_simulate", {"simulate", "s.yaml", "--duration", "0.1", "--out", "o"}, 2,
                  b.field, {{"s.yaml", b.text}}, nullptr, "o"});
  }
  // The same scene errors through the other subcommands (a sample of them).
  for (const auto& b : bad) {
    static const std::set<std::string> sample{"mass_nan", "duplicate_key", "name_comma", "gear_self",
                                              "resistance_huge", "billion_laughs"};
    if (!sample.count(b.tag)) continue;
    cs.push_back({"scene_" + b.tag + "_extract", {"extract", "s.yaml", "--out", "t.csv"}, 2, b.field,
                  {{"s.yaml", b.text}}, nullptr, "t.csv"});
    cs.push_back({"scene_" + b.tag + "_validate", {"validate", "s.yaml", "--out", "o"}, 2, b.field,
                  {{"s.yaml", b.text}}, nullptr, "o"});
    cs.push_back({"scene_" + b.tag + "_calibrate", {"calibrate", "s.yaml", "--write-scene", "c.yaml"}, 2, b.field,
                  {{"s.yaml", b.text}}, nullptr, "c.yaml"});
    cs.push_back({"scene_" + b.tag + "_inspect", {"inspect", "s.yaml"}, 2, b.field, {{"s.yaml", b.text}}, nullptr, "o"});
    cs.push_back({"scene_" + b.tag + "_sweep",
                  {"sweep", "s.yaml", "--vary", "bodies.crank.mass_kg=0.4:0.6:2", "--cadence-hz", "1", "--power-w",
                   "1", "--out", "w.csv"},
                  2, b.field, {{"s.yaml", b.text}}, nullptr, "w.csv"});
  }
  // A bad scene inside a suite is that scene's error; the others still run, the suite fails.
  // Overrides.
  const std::vector<std::pair<std::string, std::string>> sets{
      {"bodies.crank.mass_kg=nan", "mass_kg"},   {"bodies.crank.mass_kg=-1", "mass_kg"},
      {"bodies.crank.mass_kg=abc", "mass_kg"},   {"nosuch.key=1", "nosuch"},
      {"=1", "--set"},                            {"bodies.crank.mass_kg", "--set"},
      {"bodies.7.mass_kg=1", "7"},                {"name=a,b", "not a valid name"},
      {"simulation.tolerance=0", "tolerance"},    {"initial.qdot=inf", "qdot"},
      {"gravity.g_m_s2.1=1e400", "g_m_s2"},      {"bodies.crank.points.B.0=1e9", "B"}};
  for (size_t k = 0; k < sets.size(); ++k)
    cs.push_back({"set_bad" + std::to_string(k),
                  {"simulate", "fourbar", "--duration", "0.1", "--set", sets[k].first, "--out", "o"}, 2,
                  sets[k].second, {}, nullptr, "o"});
  // The bicycle-leg generator refuses values it cannot mean instead of replacing them.
  const std::vector<std::string> leg{"bicycle_leg.subject.height_m=-1.7", "bicycle_leg.subject.mass_kg=0",
                                     "bicycle_leg.crank_length_m=-0.17", "bicycle_leg.hip_torque_Nm=-5",
                                     "bicycle_leg.flywheel.inertia_kgm2=0", "bicycle_leg.subject.height_m=nan",
                                     "bicycle_leg.flywheel.gear_ratio=1e9"};
  for (size_t k = 0; k < leg.size(); ++k)
    cs.push_back({"bicycle_leg_bad" + std::to_string(k),
                  {"simulate", "bicycle", "--duration", "0.1", "--set", leg[k], "--out", "o"}, 2,
                  leg[k].substr(0, leg[k].find('=')), {}, nullptr, "o"});
  // Things that used to hang: each now refused before work, or bounded.
  cs.push_back({"hang_dt_out_tiny", {"simulate", "fourbar", "--dt-out", "1e-12", "--out", "o"}, 2, "--dt-out", {},
                nullptr, "o"});
  cs.push_back({"oom_grid_tiny", {"extract", "fourbar", "--grid-deg", "1e-6", "--out", "t.csv"}, 2, "--grid-deg", {},
                nullptr, "t.csv"});
}

// Reduced tables: another scene's table, an old table, and broken files are refused
// before any integration; the fourbar's own table (made by the setup) runs.
void tables(std::vector<Case>& cs) {
  const std::string fourbar45 = slurp(fs::path(RDYN_SOURCE_DIR) / "tests/fuzz/table_corpus/fourbar-45.csv");
  auto reduced = [](const std::string& scene) {
    return std::vector<std::string>{"simulate", scene, "--model", "reduced", "--table", "t.csv", "--duration", "0.2",
                                    "--out", "o"};
  };
  const std::string body = fourbar45.substr(fourbar45.find('\n') + 1);
  const std::string header = fourbar45.substr(0, fourbar45.find('\n') + 1);
  const std::string rows = body.substr(body.find('\n') + 1);
  const std::string columns = body.substr(0, body.find('\n') + 1);
  struct Bad {
    std::string tag, scene, table, message;
  };
  std::string ragged = fourbar45;
  ragged.insert(ragged.rfind('\n', ragged.size() - 2), ",1");
  const std::vector<Bad> bad{
      {"other_scene", "bicycle", fourbar45, "different scene"},
      {"old_without_header", "fourbar", body, "not an rdyn reduced table"},
      {"nan_value", "fourbar", edit(fourbar45, "0.0044901048077564294", "nan"), "finite"},
      {"inf_value", "fourbar", edit(fourbar45, "0.0044901048077564294", "-inf"), "finite"},
      {"ragged_row", "fourbar", ragged, "t.csv"},
      {"unknown_column", "fourbar", edit(fourbar45, "q_deg,m1,", "q_deg,bogus,"), "bogus"},
      {"duplicate_column", "fourbar", edit(fourbar45, "q_deg,m1,m2,", "q_deg,m1,m1,"), "m1"},
      {"grid_not_increasing", "fourbar", header + columns + rows.substr(rows.find('\n') + 1) + rows.substr(0, rows.find('\n') + 1), "t.csv"},
      {"header_only", "fourbar", header + columns, "t.csv"},
      {"empty", "fourbar", "", "t.csv"},
      {"binary", "fourbar", std::string("\x89PNG\r\n\x1a\n\0\0", 10), "t.csv"},
      {"hash_forged_garbage", "fourbar", edit(fourbar45, "scene=61b0f9529d56b22b", "scene=zzzz"), "t.csv"},
  };
  for (const auto& b : bad)
    cs.push_back({"table_" + b.tag, reduced(b.scene), 2, b.message, {{"t.csv", b.table}}, nullptr, "o"});
  cs.push_back({"table_missing", reduced("fourbar"), 2, "t.csv", {}, nullptr, "o"});
  cs.push_back({"table_is_folder", reduced("fourbar"), 2, "t.csv", {{"t.csv/x", "x"}}, nullptr, "o"});
  cs.push_back({"table_own_scene_runs", reduced("fourbar"), 0, "", {}, [](const fs::path& d) {
                  const RdynRun r = run_rdyn({"extract", "fourbar", "--out", "t.csv"}, d);
                  EXPECT_EQ(r.status, 0) << r.err;
                }});
  cs.push_back({"table_set_changes_mechanism", [&] {
                  auto a = reduced("fourbar");
                  a.insert(a.end() - 2, {"--set", "bodies.crank.points.B.0=0.09"});
                  return a;
                }(), 2, "different scene", {}, [](const fs::path& d) {
                  const RdynRun r = run_rdyn({"extract", "fourbar", "--out", "t.csv"}, d);
                  EXPECT_EQ(r.status, 0) << r.err;
                }, "o"});
}

// Ground truth that would be silently wrong: a mechanism that is not one DOF although the
// joint count says so, an integration that loses its energy, several forces on one joint.
void ground_truth(std::vector<Case>& cs) {
  const std::string fb = scene_text("fourbar");
  // A free two-link pendulum (+2 coordinates) and the loop closure given twice (2 redundant
  // rows): joints − 2·loops = 5 − 4 = 1 by count, but 3 degrees of freedom by rank.
  std::string three_dof = edit(fb, "loops:\n", "loops:\n  - {name: C2, body_a: coupler, point_a: C, body_b: rocker, point_b: C}\n");
  three_dof = edit(three_dof, "joints:\n",
                   "joints:\n  - {name: p1, type: revolute, parent: ground, parent_point: A, child: p1, guess_deg: -90}\n"
                   "  - {name: p2, type: revolute, parent: p1, parent_point: E, child: p2, guess_deg: 0}\n");
  three_dof = edit(three_dof, "bodies:\n",
                   "bodies:\n  - {name: p1, mass_kg: 0.1, com_m: [0.05, 0], inertia_kgm2: 1.0e-4, points: {E: [0.1, 0]}}\n"
                   "  - {name: p2, mass_kg: 0.1, com_m: [0.05, 0], inertia_kgm2: 1.0e-4}\n");
  for (const std::string cmd : {"simulate", "extract"}) {
    std::vector<std::string> args{cmd, "s.yaml", "--out", cmd == "simulate" ? "o" : "t.csv"};
    cs.push_back({cmd + "_not_one_dof_by_rank", args, 2, "degrees of freedom", {{"s.yaml", three_dof}}, nullptr,
                  args.back()});
  }
  // Simbody's Runge–Kutta–Merson at 1e-6 left the parallelogram's branch at an aligned position
  // (and then lost its energy, 5.9 of 5.9 J); the singular passages cross those positions.
  const std::string pg = (fs::path(RDYN_SCENES) / "hard/parallelogram.yaml").string();
  cs.push_back({"loose_tolerance_through_singular_positions", {"simulate", pg, "--tolerance", "1e-6", "--out", "o"}, 0,
                ""});
  // The reduced model at 0.2 s fixed steps on the light flywheel ends with 18.6 J of its ~25 J
  // unaccounted for: it closed exit 0 before (the divergence guard only stops blow-ups).
  cs.push_back({"reduced_energy_lost_by_a_coarse_fixed_step",
                {"simulate", (fs::path(RDYN_SCENES) / "hard/light-flywheel.yaml").string(), "--model", "reduced",
                 "--grid-deg", "10", "--reduced-integrator", "rk4-fixed", "--fixed-step", "0.2", "--duration", "6",
                 "--out", "o"},
                1, "reduced model's energy balance does not close", {}, nullptr, "o"});
  // A four-bar at its Grashof change point (crank 1, coupler 3, rocker 2, ground 2): through its
  // rank loss at 0° the branch repeats only every two turns, so no table closes one turn; the
  // message said "extract on a finer grid", which never helps here.
  const std::string change =
      "name: change\nground_points: {A: [0, 0], D: [2, 0]}\nbodies:\n"
      "  - {name: crank, mass_kg: 1, com_m: [0.5, 0], inertia_kgm2: 0.0833, points: {B: [1, 0]}}\n"
      "  - {name: coupler, mass_kg: 3, com_m: [1.5, 0], inertia_kgm2: 2.25, points: {C: [3, 0]}}\n"
      "  - {name: rocker, mass_kg: 2, com_m: [1, 0], inertia_kgm2: 0.667, points: {C: [2, 0]}}\njoints:\n"
      "  - {name: crank, type: revolute, parent: ground, parent_point: A, child: crank, guess_deg: 90}\n"
      "  - {name: coupler, type: revolute, parent: crank, parent_point: B, child: coupler, guess_deg: -74.75}\n"
      "  - {name: rocker, type: revolute, parent: ground, parent_point: D, child: rocker, guess_deg: 63.43}\n"
      "loops:\n  - {name: C, body_a: coupler, point_a: C, body_b: rocker, point_b: C}\nindependent: crank\n"
      "gravity: {enabled: true}\ninitial: {q_deg: 90, qdot: 5}\n";
  cs.push_back({"extract_change_point_linkage_names_its_rank_loss", {"extract", "s.yaml", "--out", "t.csv"}, 2,
                "repeats only every two turns", {{"s.yaml", change}}, nullptr, "t.csv"});
  // CPodes at 1e-2 keeps the four-bar's branch but loses its energy (0.7 of 2.5 J).
  cs.push_back({"energy_lost_by_a_loose_integrator",
                {"simulate", "fourbar", "--integrator", "cpodes", "--tolerance", "1e-2", "--out", "o"}, 1,
                "energy balance does not close", {}, nullptr, "o"});
  // The knee along and across the shank: two constraint forces on one joint, both models.
  const std::string two = edit(scene_text("bicycle"), "    - {name: knee, joint: knee_r, direction: ankle}\n",
                               "    - {name: knee, joint: knee_r, direction: ankle}\n"
                               "    - {name: knee_across, joint: knee_r, direction: [1, 0]}\n");
  for (const std::string model : {"full", "reduced"})
    cs.push_back({"two_forces_on_one_joint_" + model,
                  {"simulate", "s.yaml", "--model", model, "--duration", "0.3", "--out", "o"}, 0, "",
                  {{"s.yaml", two}}, nullptr, "", {}, [](const fs::path& d, const RdynRun&) {
                    const std::string csv = slurp(d / "o/timeseries.csv");
                    EXPECT_NE(csv.find(",F_knee,F_knee_across\n"), std::string::npos) << csv.substr(0, 200);
                  }});
}

// Found by a hostile tester (issue #9 session notes): each now refused or written cleanly.
void found_later(std::vector<Case>& cs) {
  // A four-bar driven by a crank torque, without gravity and without constraint forces.
  std::string driven = edit(scene_text("fourbar"), "loads:\n",
                            "loads:\n  - {type: joint_torque, name: drive, joint: crank, torque_Nm: 0.5}\n");
  driven = edit(driven, "gravity: {enabled: true, g_m_s2: [0, -9.81]}", "gravity: {enabled: false}");
  const std::string no_forces = driven.substr(0, driven.find("outputs:")) + driven.substr(driven.find("initial:"));
  cs.push_back({"sweep_without_constraint_force_writes_no_nan",
                {"sweep", "nf.yaml", "--vary", "bodies.crank.mass_kg=0.4:0.6:2", "--cadence-hz", "1", "--power-w",
                 "0.5", "--out", "w.csv"},
                0, "", {{"nf.yaml", no_forces}}});
  cs.push_back({"sweep_same_key_twice",
                {"sweep", "bicycle", "--vary", "bicycle_leg.subject.height_m=1.6:1.7:2", "--vary",
                 "bicycle_leg.subject.height_m=1.8:1.9:2", "--out", "w.csv"},
                2, "varied twice", {}, nullptr, "w.csv"});
  cs.push_back({"calibrate_file_name_cannot_inject_yaml",
                {"calibrate", "x\ngravity: {enabled: true}\n#.yaml", "--cadence-hz", "1", "--power-w", "0.5",
                 "--write-scene", "cal.yaml"},
                0, "", {{"x\ngravity: {enabled: true}\n#.yaml", driven}}, nullptr, "", {},
                [](const fs::path& d, const RdynRun&) {
                  const RdynRun again = run_rdyn({"simulate", "cal.yaml", "--duration", "0.1", "--out", "o"}, d);
                  EXPECT_EQ(again.status, 0) << again.err;  // the written scene loads: nothing was injected
                }});
  // Named drive loads (issue #14): a bad --load or validation.calibrate.load is bad input naming
  // its field, and --write-scene leaves nothing behind.
  for (const auto& [tag, load, message] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"unknown", "nope", "field '--load': no joint_torque, point_force or motor named 'nope'"},
           {"resistance", "flywheel_resistance", "is a resistance"},
           {"bad_name", "a\nb", "field '--load'"},
           {"generated_write", "hip_torque_r", "field '--write-scene'"},
           {"empty", "", "an empty name names no load"}})
    cs.push_back({"calibrate_load_" + tag, {"calibrate", "bicycle", "--load", load, "--write-scene", "cal.yaml"}, 2,
                  message, {}, nullptr, "cal.yaml"});
  cs.push_back({"sweep_load_unknown",
                {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2", "--load", "nope", "--out", "w.csv"},
                2, "field '--load'", {}, nullptr, "w.csv"});
  cs.push_back({"calibrate_load_in_scene_unknown", {"calibrate", "d.yaml", "--write-scene", "cal.yaml"}, 2,
                "field 'validation.calibrate.load': no joint_torque, point_force or motor named 'ghost'",
                {{"d.yaml", driven + "validation: {calibrate: {cadence_Hz: 1, load: ghost}}\n"}}, nullptr, "cal.yaml"});
  cs.push_back({"calibrate_load_in_scene_empty", {"calibrate", "d.yaml", "--write-scene", "cal.yaml"}, 2,
                "field 'validation.calibrate.load': an empty name names no load",
                {{"d.yaml", driven + "validation: {calibrate: {cadence_Hz: 1, load: ''}}\n"}}, nullptr, "cal.yaml"});
  // Point forces (issue #13): points that coincide where the mechanism assembles are bad input
  // naming point_b's line (both models); points that meet during a run are a numerical failure;
  // a '+' list with a repeated name, and a tension beyond 1e6 N through --set, are bad input.
  const std::string pulled =
      "name: pulled\nground_points: {O: [0, 0], G: [0.1, 0]}\n"
      "bodies: [{name: crank, mass_kg: 1.0, com_m: [0.05, 0], inertia_kgm2: 2.0e-3, points: {B: [0.1, 0]}}]\n"
      "joints: [{name: crank, type: revolute, parent: ground, parent_point: O, child: crank}]\n"
      "independent: crank\nloads:\n"
      "  - {type: point_force, name: m, body_a: ground, point_a: G, body_b: crank, point_b: B, force_N: 5}\n"
      "initial: {q_deg: 0, qdot: 1}\n";
  for (const std::string model : {"full", "reduced"})
    cs.push_back({"point_force_coincident_" + model, {"simulate", "p.yaml", "--model", model, "--out", "o"}, 2,
                  "p.yaml:7: field 'loads.m.point_b': point force 'm': point_b on 'crank' lies 0 m from point_a",
                  {{"p.yaml", pulled}}, nullptr, "o"});
  cs.push_back({"point_force_points_meet",
                {"simulate", "s.yaml", "--model", "full", "--out", "o"}, 1, "point force 'm': its points met",
                {{"s.yaml", "name: slide\nground_points: {O: [0, 0]}\n"
                            "bodies: [{name: block, mass_kg: 1.0, inertia_kgm2: 1.0e-3}]\n"
                            "joints: [{name: s, type: prismatic, parent: ground, parent_point: O, child: block, "
                            "axis: [1, 0], guess_m: 0.3}]\n"
                            "independent: s\nindependent_range: [-1, 1]\nloads:\n"
                            "  - {type: point_force, name: m, body_a: ground, point_a: O, body_b: block, "
                            "point_b: [0, 0], force_N: 10}\n"
                            "initial: {q: 0.3, qdot: 0}\nsimulation: {duration_s: 1}\n"}},
                nullptr, "o"});
  // Points that meet between grid points (a crank pin passing through a ground point at 3°, the
  // 10° grid's points at 0° and 10°): the reduced model stops at extraction as the full one does
  // during the run, both exit 1 naming the load. 0.9 mm short of meeting, both run.
  const std::string through =
      "name: pulled\nground_points: {O: [0, 0], G: [0.0998629535, 0.0052335956]}\n"
      "bodies: [{name: crank, mass_kg: 1.0, com_m: [0.05, 0], inertia_kgm2: 2.0e-3, points: {B: [0.1, 0]}}]\n"
      "joints: [{name: crank, type: revolute, parent: ground, parent_point: O, child: crank}]\n"
      "independent: crank\nloads:\n"
      "  - {type: point_force, name: m, body_a: ground, point_a: G, body_b: crank, point_b: B, force_N: 5}\n"
      "initial: {q_deg: 90, qdot: 10}\nsimulation: {duration_s: 2}\n";
  cs.push_back({"point_force_points_meet_between_grid_points_reduced",
                {"simulate", "p.yaml", "--model", "reduced", "--out", "o"}, 1,
                "point force 'm': its points meet near q = ", {{"p.yaml", through}}, nullptr, "o"});
  cs.push_back({"point_force_points_meet_between_grid_points_full",
                {"simulate", "p.yaml", "--model", "full", "--out", "o"}, 1, "point force 'm': its points met",
                {{"p.yaml", through}}, nullptr, "o"});
  cs.push_back({"point_force_points_meet_between_grid_points_extract", {"extract", "p.yaml", "--out", "t.csv"}, 1,
                "point force 'm': its points meet near q = ", {{"p.yaml", through}}, nullptr, "t.csv"});
  for (const std::string model : {"reduced", "full"})
    cs.push_back({"point_force_points_nearly_meet_" + model, {"simulate", "p.yaml", "--model", model, "--out", "o"}, 0,
                  "", {{"p.yaml", edit(through, "G: [0.0998629535, 0.0052335956]", "G: [0.0986, 0.0086]")}}});
  cs.push_back({"point_force_set_huge",
                {"simulate", "bicycle-muscle", "--set", "loads.gluteus_r.force_N=2e6", "--out", "o"}, 2,
                "field '--set loads.gluteus_r.force_N'", {}, nullptr, "o"});
  cs.push_back({"calibrate_load_list_repeated",
                {"calibrate", "bicycle-muscle", "--load", "gluteus_r+gluteus_r", "--write-scene", "cal.yaml"}, 2,
                "field '--load': 'gluteus_r' is named twice", {}, nullptr, "cal.yaml"});
  for (const std::string reserved : {"summary.json", "index.html"})
    cs.push_back({"suite_name_" + reserved.substr(0, reserved.find('.')), {"validate", "--suite", "s", "--out", "o"}, 2,
                  "suite's own output", {{"s/" + reserved + ".yaml", scene_text("fourbar")}}, nullptr, "o"});
  for (const auto& [tag, set] : std::vector<std::pair<std::string, std::string>>{{"noequals", "noequals"}, {"empty_key", "=1"}})
    cs.push_back({"suite_bad_set_" + tag, {"validate", "--suite", "s", "--set", set, "--out", "o"}, 2, "--set",
                  {{"s/a.yaml", scene_text("fourbar")}}, nullptr, "o"});
  // Endless or special files as scenes: refused before opening (not a regular file).
  for (const std::string dev : {"/dev/zero", "/dev/urandom"}) {
    cs.push_back({"scene_from_" + dev.substr(5), {"simulate", dev, "--out", "o"}, 2,
                  "not a regular file (a character device)", {}, nullptr, "o"});
    cs.push_back({"inspect_scene_from_" + dev.substr(5), {"inspect", dev}, 2, "not a regular file (a character device)",
                  {}, nullptr, "o"});
  }
  // A FIFO without a writer (opening it to read would block), a folder: refused by stat before
  // any open, as scenes of every command and as tables. The FIFO is made, never opened here.
  RunLimits quick;
  quick.time_limit_s = 20;  // a blocked open would hang: fail fast
  auto fifo = [](const std::string& name) {
    return [name](const fs::path& d) { ASSERT_EQ(mkfifo((d / name).c_str(), 0644), 0); };
  };
  for (const auto& args : std::vector<std::vector<std::string>>{
           {"simulate", "p.yaml", "--out", "o"},
           {"inspect", "p.yaml"},
           {"expand", "p.yaml", "--out", "o"},
           {"extract", "p.yaml", "--out", "o"},
           {"calibrate", "p.yaml", "--cadence-hz", "1", "--write-scene", "o"},
           {"optimize", "p.yaml", "--out", "o"},
           {"validate", "p.yaml", "--quick", "--out", "o"}})
    cs.push_back({"scene_fifo_" + args[0], args, 2, "p.yaml: not a regular file (a FIFO)", {}, fifo("p.yaml"), "o", quick});
  cs.push_back({"report_summary_fifo", {"report", "s.json", "--out", "o"}, 2, "s.json: not a regular file (a FIFO)", {},
                fifo("s.json"), "o", quick});
  cs.push_back({"scene_folder", {"simulate", "p.yaml", "--out", "o"}, 2, "p.yaml: is a folder, not a scene file", {},
                [](const fs::path& d) { fs::create_directory(d / "p.yaml"); }, "o"});
  cs.push_back({"table_fifo", {"simulate", "fourbar", "--model", "reduced", "--table", "t.csv", "--out", "o"}, 2,
                "t.csv: not a regular file (a FIFO)", {}, fifo("t.csv"), "o"});
  cs.push_back({"table_folder", {"simulate", "fourbar", "--model", "reduced", "--table", "t.csv", "--out", "o"}, 2,
                "t.csv: not a regular file (a folder)", {}, [](const fs::path& d) { fs::create_directory(d / "t.csv"); },
                "o"});
  // An error in a --set value names the --set argument, not the file's line (the key is in the file).
  cs.push_back({"calibrate_set_load_unknown",
                {"calibrate", "bicycle-muscle", "--set", "validation.calibrate.load=nope", "--write-scene", "cal.yaml"},
                2, "field '--set validation.calibrate.load': no joint_torque, point_force or motor named 'nope'", {},
                nullptr, "cal.yaml", {}, [](const fs::path&, const RdynRun& r) {
                  EXPECT_FALSE(std::regex_search(r.err, std::regex("bicycle-muscle\\.yaml:[0-9]"))) << "names the file's line: "
                                                                                    << r.err;
                }});
  // Joint outputs and branches (issue #10): bad names and values are exit 2 naming the field.
  for (const auto& [tag, set, field] : std::vector<std::tuple<std::string, std::string, std::string>>{
           {"joints_word", "outputs.joints=some", "outputs.joints"},
           {"shaking_word", "outputs.shaking=maybe", "outputs.shaking"},
           {"branch_joint", "loops.C.branch.joint=nosuch", "branch"},
           {"branch_sign", "loops.C.branch.sign=0", "branch"}})
    for (const std::string cmd : {"simulate", "inspect"}) {
      std::vector<std::string> args{cmd, "fourbar", "--set", set};
      if (tag.rfind("branch", 0) == 0)
        args.insert(args.end(), {"--set", tag == "branch_joint" ? "loops.C.branch.sign=positive"
                                                                  : "loops.C.branch.joint=rocker"});
      if (cmd == "simulate") args.insert(args.end(), {"--duration", "0.1", "--out", "o"});
      cs.push_back({"outputs_" + tag + "_" + cmd, args, 2, field, {}, nullptr, "o"});
    }
  cs.push_back({"suite_dangling_link_named_yaml", {"validate", "--suite", "s", "--out", "o"}, 2, "not a readable scene",
                {{"s/a.yaml", scene_text("fourbar")}}, [](const fs::path& d) {
                  fs::create_symlink("nowhere.yaml", d / "s/b.yaml");
                }, "o"});
  // A mechanism at rest: every error is 0 of a peak of 0 — a failure, not a pass.
  cs.push_back({"validate_mechanism_at_rest_fails",
                {"validate", "fourbar", "--quick", "--set", "gravity.enabled=false", "--set", "initial.qdot=0", "--out",
                 "o"},
                1, "does not move"});
  const std::vector<std::vector<std::string>> other_model{{"--model", "reduced", "--tolerance", "nan"},
                                                          {"--model", "full", "--reduced-tolerance", "nan"},
                                                          {"--model", "full", "--fixed-step", "nan"},
                                                          {"--model", "full", "--grid-deg", "7"},
                                                          {"--model", "reduced", "--fixed-step", "1e-12"}};
  for (size_t k = 0; k < other_model.size(); ++k) {
    std::vector<std::string> args{"simulate", "fourbar", "--duration", "0.1"};
    args.insert(args.end(), other_model[k].begin(), other_model[k].end());
    args.insert(args.end(), {"--out", "o"});
    cs.push_back({"simulate_other_model_option_checked" + std::to_string(k), args, 2, other_model[k][2], {}, nullptr, "o"});
  }
  // A table has its grid: a --grid-deg beside it was ignored in silence.
  cs.push_back({"simulate_table_and_grid_deg",
                {"simulate", "fourbar", "--model", "reduced", "--table", "t.csv", "--grid-deg", "5", "--out", "o"}, 2,
                "--grid-deg: the --table has its own grid", {}, nullptr, "o"});
}

// Leftovers of issue #23: each refused with file, line and field (or the option), or written
// as documented.
void issue23(std::vector<Case>& cs) {
  // The final state is the last row, also when --dt-out does not divide --duration.
  for (const std::string model : {"reduced", "full"})
    cs.push_back({"simulate_last_row_at_duration_" + model,
                  {"simulate", "fourbar", "--model", model, "--duration", "1", "--dt-out", "0.3", "--out", "o"}, 0, "",
                  {}, nullptr, "", {}, [](const fs::path& d, const RdynRun&) {
                    std::istringstream csv(slurp(d / "o/timeseries.csv"));
                    std::string line;
                    std::getline(csv, line);  // header
                    std::vector<double> t;
                    while (std::getline(csv, line)) t.push_back(std::stod(line.substr(0, line.find(','))));
                    ASSERT_EQ(t.size(), 5u);
                    for (size_t i = 0; i + 1 < t.size(); ++i) EXPECT_NEAR(t[i], 0.3 * i, 1e-12) << i;
                    EXPECT_EQ(t.back(), 1.0);
                  }});
  // A second YAML document was silently dropped.
  const std::string fb = scene_text("fourbar");
  const int fb_lines = static_cast<int>(std::count(fb.begin(), fb.end(), '\n'));
  for (const std::string cmd : {"simulate", "inspect"})
    cs.push_back({"second_yaml_document_" + cmd,
                  cmd == "inspect" ? std::vector<std::string>{cmd, "s.yaml"}
                                   : std::vector<std::string>{cmd, "s.yaml", "--out", "o"},
                  2,
                  fmt::format("s.yaml:{}: a second YAML document (after '---')", fb_lines + 1),
                  {{"s.yaml", fb + "---\ngravity: {enabled: false}\n"}}, nullptr, "o"});
  // A value key in the other joint type's unit was read in the joint's own unit.
  const std::string sc = scene_text("slider-crank");
  auto line_of = [](const std::string& text, const std::string& what) {
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(text.find(what)), '\n'));
  };
  const int load_line = line_of(sc, "joint: slider, force_N"), motor_line = line_of(sc, "stall_torque_Nm");
  using Edit = std::tuple<std::string, std::string, std::string, std::string>;  // tag, from, to, message
  for (const auto& [tag, from, to, message] : std::vector<Edit>{
           {"torque_on_prismatic", "joint: slider, force_N:", "joint: slider, torque_Nm:",
            fmt::format("s.yaml:{}: field 'loads[1].torque_Nm': joint 'slider' is prismatic (forces in N, speeds in "
                        "m/s): give force_N instead of torque_Nm", load_line)},
           {"force_on_revolute", "joint: slider, force_N:", "joint: crank, force_N:",
            fmt::format("s.yaml:{}: field 'loads[1].force_N': joint 'crank' is revolute (torques in N·m, speeds in "
                        "rad/s): give torque_Nm instead of force_N", load_line)},
           {"stall_torque_on_slider", "joint: crank, stall_torque_Nm", "joint: slider, stall_torque_Nm",
            fmt::format("s.yaml:{}: field 'loads[0].stall_torque_Nm': joint 'slider' is prismatic (forces in N, speeds "
                        "in m/s): give stall_force_N instead of stall_torque_Nm", motor_line)}})
    cs.push_back({"unit_key_" + tag, {"simulate", "s.yaml", "--out", "o"}, 2, message, {{"s.yaml", edit(sc, from, to)}},
                  nullptr, "o"});
  // Numbers on the command line: decimal only, in range, said as typed.
  const std::vector<std::string> sweep{"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=60:70:2"};
  auto with = [](std::vector<std::string> a, std::vector<std::string> more) {
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  cs.push_back({"sweep_threads_zero", with(sweep, {"--threads", "0", "--out", "s.csv"}), 2,
                "--threads: must be a finite number in [1, 256] (got 0)", {}, nullptr, "s.csv"});
  cs.push_back({"sweep_cadence_zero", with(sweep, {"--cadence-hz", "0", "--out", "s.csv"}), 2, "--cadence-hz", {},
                nullptr, "s.csv"});
  cs.push_back({"sweep_threads_hex", with(sweep, {"--threads", "0x10", "--out", "s.csv"}), 2,
                "--threads: expected a whole decimal number, got '0x10'", {}, nullptr, "s.csv"});
  cs.push_back({"sweep_vary_hex",
                {"sweep", "bicycle", "--vary", "bicycle_leg.hip_torque_Nm=0x3c:70:2", "--out", "s.csv"}, 2,
                "a of a:b:n: expected a decimal number, got '0x3c'", {}, nullptr, "s.csv"});
  cs.push_back({"simulate_duration_hex", {"simulate", "fourbar", "--duration", "0x10", "--out", "o"}, 2,
                "--duration: expected a decimal number, got '0x10' (digits 0-9 only", {}, nullptr, "o"});
  cs.push_back({"simulate_duration_underflows", {"simulate", "fourbar", "--duration", "1e-400", "--out", "o"}, 2,
                "--duration: '1e-400' is out of range: it underflows", {}, nullptr, "o"});
  cs.push_back({"simulate_duration_overflows", {"simulate", "fourbar", "--duration", "1e400", "--out", "o"}, 2,
                "--duration: '1e400' is out of range", {}, nullptr, "o"});
  // --force into a folder where timeseries.csv is a folder: refused with nothing changed.
  cs.push_back({"simulate_force_into_folder_named_like_a_result",
                {"simulate", "fourbar", "--duration", "0.1", "--out", "proj", "--force"}, 2,
                "proj/timeseries.csv: is a folder; rdyn would write a file of that name there. Nothing was written",
                {{"proj/run.json", "{\"mine\": true}\n"}, {"proj/timeseries.csv/keep.txt", "kept\n"}}, nullptr, "",
                {}, [](const fs::path& d, const RdynRun&) {
                  EXPECT_FALSE(fs::exists(d / "proj/.rdyn-output"));
                  EXPECT_EQ(std::distance(fs::directory_iterator(d / "proj"), fs::directory_iterator()), 2);
                }});
  // "0: no drive" (docs/scene-format.md) holds with the bicycle's optimize block in place; only
  // `rdyn optimize` needs the design loads, and says so when there are none.
  cs.push_back({"simulate_bicycle_without_drive",
                {"simulate", "bicycle", "--set", "bicycle_leg.hip_torque_Nm=0", "--duration", "0.2", "--out", "o"}, 0,
                ""});
  cs.push_back({"optimize_bicycle_without_drive",
                {"optimize", "bicycle", "--set", "bicycle_leg.hip_torque_Nm=0", "--out", "o"}, 2,
                "bicycle.yaml: field 'loads': optimize shapes joint torques and the scene has none", {}, nullptr, "o"});
  // Messages with file, line and field in plain words.
  {
    std::string fb2 = edit(fb, "{name: coupler, type: revolute", "{name: b_crank, type: revolute");
    fb2 = edit(fb2, "    - {name: rocker_axial, joint: rocker, direction: C}\n",
               "    - {name: rocker_axial, joint: rocker, direction: C}\n    - {name: x, joint: rocker, direction: C}\n"
               "    - {name: x_b, joint: rocker, direction: C}\n");
    const int x_b_line = line_of(fb2, "name: x_b");
    for (const std::string cmd : {"simulate", "extract"})
      cs.push_back({"column_collision_" + cmd, {cmd, "s.yaml", "--out", "o"}, 2,
                    fmt::format("s.yaml:{}: field 'outputs.constraint_forces[2].name': constraint force 'x' with joint "
                                "'b_crank' and constraint force 'x_b' with joint 'crank' both make the reduced table's "
                                "column 'rx_x_b_crank'",
                                x_b_line),
                    {{"s.yaml", fb2}}, nullptr, "o"});
    const std::string reserved = edit(fb, "    - {name: rocker_axial, joint: rocker, direction: C}\n",
                                      "    - {name: rocker_axial, joint: rocker, direction: C}\n"
                                      "    - {name: R_crank_gx, joint: crank, direction: [1, 0]}\n");
    const int reserved_line = line_of(reserved, "R_crank_gx");
    cs.push_back({"reserved_reaction_line_name", {"simulate", "s.yaml", "--model", "reduced", "--out", "o"}, 2,
                  fmt::format("s.yaml:{}: field 'outputs.constraint_forces[1].name': 'R_crank_gx' is reserved",
                              reserved_line),
                  {{"s.yaml", reserved}}, nullptr, "o"});
    // A force named like the speed took the speed's verdict in validate.
    const std::string as_speed = edit(fb, "    - {name: rocker_axial, joint: rocker, direction: C}\n",
                                      "    - {name: qdot, joint: rocker, direction: C}\n");
    cs.push_back({"force_named_like_the_speed", {"validate", "s.yaml", "--quick", "--out", "o"}, 2,
                  fmt::format("s.yaml:{}: field 'outputs.constraint_forces[0].name': 'qdot' is reserved",
                              line_of(as_speed, "name: qdot")),
                  {{"s.yaml", as_speed}}, nullptr, "o"});
    // Calibrate and optimize need a coordinate that turns: a stroke is refused naming the line of
    // `independent` (the message named the field alone; issue #23's excavator bucket).
    const std::string sl = scene_text("slider-crank-slider");
    const int indep_line = line_of(sl, "independent: slider");
    cs.push_back({"calibrate_a_stroke", {"calibrate", "s.yaml", "--cadence-hz", "0.5"}, 2,
                  fmt::format("s.yaml:{}: field 'independent': calibration holds a mean rate in rev/s", indep_line),
                  {{"s.yaml", sl}}});
    cs.push_back({"optimize_a_stroke", {"optimize", "s.yaml", "--cadence-hz", "0.5", "--out", "o"}, 2,
                  fmt::format("s.yaml:{}: field 'independent': optimize shapes loads over a revolute", indep_line),
                  {{"s.yaml", sl}}, nullptr, "o"});
  }
  // A table file edited by hand: a negative m1, a missing column. Each names the table's line.
  // An extracted table, edited. Its content checksum is dropped (keep_checksum false) so that the
  // checks behind it are reached (a table without one is read, with a warning); kept, the edit is
  // refused by the checksum itself.
  auto edited_table = [](std::function<std::string(std::vector<std::vector<std::string>>&)> change,
                         bool keep_checksum = false) {
    return [change, keep_checksum](const fs::path& d) {
      const RdynRun r = run_rdyn({"extract", "fourbar", "--out", "t.csv"}, d);
      ASSERT_EQ(r.status, 0) << r.err;
      std::string text = slurp(d / "t.csv");
      const size_t sum = text.find(" content=");
      ASSERT_NE(sum, std::string::npos) << "extract writes a content checksum";
      if (!keep_checksum) text.erase(sum, 9 + 16);
      std::istringstream in(text);
      std::vector<std::vector<std::string>> cells;  // comment lines as one cell
      for (std::string line; std::getline(in, line);) {
        cells.emplace_back();
        if (line.rfind("#", 0) == 0) {
          cells.back().push_back(line);
          continue;
        }
        std::istringstream l(line);
        for (std::string cell; std::getline(l, cell, ',');) cells.back().push_back(cell);
      }
      std::ofstream(d / "t.csv") << change(cells);
    };
  };
  auto join = [](const std::vector<std::vector<std::string>>& cells) {
    std::string out;
    for (const auto& row : cells) {
      for (size_t k = 0; k < row.size(); ++k) out += (k ? "," : "") + row[k];
      out += "\n";
    }
    return out;
  };
  // The header is the first line that is not a comment; the table's line numbers are 1-based.
  auto header_index = [](const std::vector<std::vector<std::string>>& cells) {
    size_t h = 0;
    while (cells[h][0].rfind("#", 0) == 0) ++h;
    return h;
  };
  cs.push_back({"table_negative_m1", {"simulate", "fourbar", "--model", "reduced", "--table", "t.csv", "--out", "o"}, 2,
                "column 'm1' (the reduced inertia, kg·m² or kg) must be positive, got -0.5", {},
                edited_table([=](std::vector<std::vector<std::string>>& cells) {
                  cells[header_index(cells) + 3][1] = "-0.5";
                  return join(cells);
                }),
                "o", {}, [](const fs::path&, const RdynRun& r) {
                  EXPECT_TRUE(std::regex_search(r.err, std::regex("t\\.csv:[0-9]+: column 'm1'"))) << r.err;
                }});
  cs.push_back({"table_value_edited_under_its_checksum",
                {"simulate", "fourbar", "--model", "reduced", "--table", "t.csv", "--out", "o"}, 2,
                "the table's content does not match its checksum", {},
                edited_table(
                    [=](std::vector<std::vector<std::string>>& cells) {
                      // m1 and m2 of one row ×3: a consistent-looking edit the other checks accept.
                      auto& row = cells[header_index(cells) + 3];
                      row[1] = fmt::format("{:.17g}", 3 * std::stod(row[1]));
                      row[2] = fmt::format("{:.17g}", 3 * std::stod(row[2]));
                      return join(cells);
                    },
                    true),
                "o", {}, [](const fs::path&, const RdynRun& r) {
                  EXPECT_TRUE(std::regex_search(r.err, std::regex("t\\.csv:1: "))) << r.err;
                }});
  cs.push_back({"table_missing_column",
                {"simulate", "fourbar", "--model", "reduced", "--table", "t.csv", "--out", "o"}, 2,
                "the column header has no column 'me1_rocker_axial', which the scene needs", {},
                edited_table([=](std::vector<std::vector<std::string>>& cells) {
                  const size_t h = header_index(cells);
                  const auto& header = cells[h];
                  const size_t c = static_cast<size_t>(
                      std::find(header.begin(), header.end(), "me1_rocker_axial") - header.begin());
                  for (size_t i = h; i < cells.size(); ++i)
                    if (c < cells[i].size()) cells[i].erase(cells[i].begin() + static_cast<long>(c));
                  return join(cells);
                }),
                "o", {}, [](const fs::path&, const RdynRun& r) {
                  EXPECT_TRUE(std::regex_search(r.err, std::regex("t\\.csv:[0-9]+: the column header"))) << r.err;
                }});
  // A kernel folder as an output folder: refused in words, no '' names.
  cs.push_back({"simulate_out_proc_self", {"simulate", "fourbar", "--duration", "0.1", "--out", "/proc/self"}, 2,
                "/proc/self: lies in /proc, the kernel's own file system", {}, nullptr, "", {},
                [](const fs::path&, const RdynRun& r) { EXPECT_EQ(r.err.find("''"), std::string::npos) << r.err; }});
  cs.push_back({"optimize_harmonics_hex", {"optimize", "bicycle", "--harmonics", "0x3", "--out", "o"}, 2,
                "--harmonics: expected a whole decimal number, got '0x3'", {}, nullptr, "o"});
}

std::vector<Case> all_cases() {
  std::vector<Case> cs;
  issue23(cs);
  found_later(cs);
  ground_truth(cs);
  bad_numbers(cs);
  outputs(cs);
  scenes(cs);
  tables(cs);
  return cs;
}

}  // namespace
