// The hostile-input suite (issue #9): every subcommand against what a careless or hostile
// user can type. Each case asserts the exit status, the message, and what is left on disk:
// nothing deleted or changed that rdyn did not write, no temporary left behind, no shell run
// (a PWNED file would appear), no NaN in an output, no hang (a time limit per case).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <functional>
#include <map>
#include <regex>

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
  std::map<std::string, std::string> files;       // written before the run; must be intact after
  std::function<void(const fs::path&)> setup;     // more set-up (FIFOs, links, folders)
  std::string out;                                // must not exist after a failure
  RunLimits limits;
  std::function<void(const fs::path&, const RdynRun&)> check;  // more assertions
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
  if (r.status != 0 && !c.out.empty())
    EXPECT_FALSE(fs::exists(fs::symlink_status(dir / c.out))) << c.out << " left after a failure";
  const std::regex non_finite("(^|,)-?(nan|inf)(,|$)", std::regex::icase | std::regex::multiline);
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    EXPECT_EQ(name.find("rdyn-tmp"), std::string::npos) << "temporary left: " << it->path();
    EXPECT_NE(name, "PWNED") << "a shell ran user text";
    std::error_code fe;
    if (it->is_regular_file(fe) && it->path().extension() == ".csv" && it->file_size(fe) < (1u << 24))
      EXPECT_FALSE(std::regex_search(slurp(it->path()), non_finite)) << "non-finite value in " << it->path();
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
  cs.push_back({"extract_to_dev_full", {"extract", "fourbar", "--out", "/dev/full"}, 2, "No space left"});
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
  // Interrupted runs leave nothing (the signal's own status: 128 + signal).
  for (const auto& [tag, sig] : std::vector<std::pair<std::string, int>>{{"int", SIGINT}, {"term", SIGTERM}, {"hup", SIGHUP}}) {
    Case c{"simulate_interrupted_" + tag, {"simulate", "bicycle", "--duration", "500", "--out", "x/o"}, 128 + sig, ""};
    c.out = "x";
    c.limits.signal_after_ms = 1500;
    c.limits.signal = sig;
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

std::vector<Case> all_cases() {
  std::vector<Case> cs;
  bad_numbers(cs);
  outputs(cs);
  return cs;
}

}  // namespace
