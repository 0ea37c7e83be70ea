// `rdyn validate` (one scene or a suite) and `rdyn report`: the validation harness run, its
// summary with the mechanism drawn and one cycle animated, the report rendered from it.
#include "validate/cli/commands.hpp"

#include <algorithm>
#include <cstdio>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <cctype>
#include <map>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "engine/forward_dynamics.hpp"
#include "engine/full_model.hpp"
#include "models/scene_yaml.hpp"
#include "models/timeseries.hpp"
#include "reduced/joint_outputs.hpp"
#include "reduced/reduced_model.hpp"
#include "reduced/simulate_reduced.hpp"
#include "validate/analysis/build_reduced.hpp"
#include "validate/analysis/calibrate.hpp"
#include "validate/analysis/calibrated_scene.hpp"
#include "validate/cli/cli_limits.hpp"
#include "validate/io/escape.hpp"
#include "validate/harness/harness.hpp"
#include "validate/report/report_tables.hpp"
#include "validate/cli/inspect.hpp"
#include "validate/cli/animate_command.hpp"
#include "engine/inspect.hpp"
#include "validate/report/report.hpp"
#include "validate/report/cycle_animation.hpp"
#include "validate/analysis/cycle_run.hpp"
#include "validate/harness/summary.hpp"
#include "validate/analysis/sweep.hpp"
#include "validate/cli/sweep_axis.hpp"
#include "validate/io/progress.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/harness/peers.hpp"
#include "validate/report/timeseries_csv.hpp"
#include "models/mjcf_export.hpp"

namespace rdyn::validate {

namespace {

void write_json(const std::string& path, const nlohmann::json& j) { write_text_file(path, j.dump(2) + "\n"); }

// The validation summary with the assembled mechanism drawn (`inspect --svg`'s drawing) and the
// record of one steady cycle of the reference animated (the last whole revolution re-run with
// every joint's coordinate, analysis/cycle_run.hpp), which the report embeds: kept in
// summary.json so that `rdyn report` re-draws them too.
nlohmann::json with_drawing(nlohmann::json summary, const models::Scene& scene, const ValidationResult& v) {
  summary["mechanism_svg"] = inspect_svg(scene, engine::calc_inspection(engine::FullModel(scene)));
  try {
    const CycleStart c = calc_last_cycle(v.reference, v.time_scale.period_s);
    summary["animation"] = animation_record(
        scene, c, simulate_cycle(scene, c),
        fmt::format("{}: full model, t = {:.4g} … {:.4g} s", scene.name, c.t_s, c.t_s + c.duration_s));
  } catch (const models::NumericalError& e) {  // the report is still written, and says why
    summary["animation_error"] = e.what();
  } catch (const std::invalid_argument& e) {  // a reference too short to animate
    summary["animation_error"] = e.what();
  }
  return summary;
}

}  // namespace

namespace {

// One scene's validation into `dir`; the scene-level summary entry for a suite.
nlohmann::json validate_one(const models::Scene& scene, const ValidationOptions& opt, const std::string& dir,
                            Progress& progress, bool& pass) {
  const ValidationResult v = run_validation(scene, opt, progress);
  const nlohmann::json full = with_drawing(summary_json(v), scene, v);
  render_report(full, dir);
  pass = v.pass;
  nlohmann::json j = {{"name", v.scene}, {"file", v.scene_file}, {"status", v.pass ? "pass" : "fail"},
                      {"note", v.note}};
  for (const char* k : {"speedup_at_matched_error", "extraction_ms", "thresholds", "reference", "steady_window",
                        "headline", "matched_full", "matched_reduced", "recommended_reduced", "recommended_full",
                        "recommended_full_as_accurate", "recommended_speedup", "verdicts", "baselines",
                        "duration_s", "per_second_measured"})
    if (full.contains(k)) j[k] = full[k];
  j["headline"] = headline(full);
  // The default grid's run (10°, finer when 10° does not resolve the mechanism; its label says).
  if (v.showcase_run >= 0) j["reduced_default"] = full["runs"][v.showcase_run];
  // Stability metrics of both models: the reference's and the default reduced run's energy
  // balance, drift per cycle, constraint violation, accepted/rejected steps, smallest step.
  j["stability"] = {{"full", full["reference"]["stability"]},
                    {"reduced", v.showcase_run >= 0 ? full["runs"][v.showcase_run] : nlohmann::json(nullptr)}};
  return j;
}

// One row of the suite index: the scene's verdicts in one cell each.
std::string suite_row(const std::string& stem, const nlohmann::json& entry) {
  const std::string status = entry.value("status", std::string("error"));
  // The scene's thresholds decide its status (validate/report/first_screen.hpp): one cell each.
  std::string verdicts;
  if (entry.contains("thresholds"))
    for (const auto& t : entry["thresholds"]) {
      const double e = t["error"].is_number() ? t["error"].get<double>() : NAN;
      const double l = t["max_error"].is_number() ? t["max_error"].get<double>() : NAN;
      const bool p = t.value("pass", false);
      verdicts += fmt::format("<span class={}>{} {} ≤ {} {}</span><br>", p ? "pass" : "fail",
                              html_escape(t.value("quantity", std::string())),
                              std::isfinite(e) ? fmt::format("{:.3g} %", 100 * e) : "n/a", fmt::format("{:.3g} %", 100 * l),
                              p ? "pass" : "FAIL");
    }
  // The recommended setting against the cheapest full run at equal or better error.
  std::string speed = "—";
  if (entry.contains("recommended_speedup") && entry["recommended_speedup"].is_number())
    speed = fmt::format("{}{:.3g}×", entry.value("recommended_full_as_accurate", true) ? "" : "≥ ",
                        entry["recommended_speedup"].get<double>());
  const std::string what = entry.contains("error") ? entry.value("error", std::string()) : entry.value("note", std::string());
  const std::string name = entry.contains("report") ? fmt::format("<a href='{0}/report.html'>{0}</a>", html_escape(stem))
                                                   : html_escape(stem);
  return fmt::format("<tr><td class=l>{0}</td><td class={1}>{1}</td><td class=l>{2}</td>"
                     "<td>{3}</td><td class=l>{4}</td></tr>",
                     name, html_escape(status), verdicts, html_escape(speed), html_escape(what));
}

}  // namespace

namespace {

// A suite scene's file stem names its report folder: it must be a plain name (no '/', no
// leading dot, no characters that need quoting in HTML or a shell) and unique in the suite.
constexpr size_t kMaxSuiteScenes = 1000;

bool plain_name(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  if (!(std::isalnum(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

std::vector<std::string> suite_files(const std::string& suite) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(suite, ec)) throw models::SceneError(suite, 0, "--suite", "not a folder of scenes");
  std::vector<std::string> files;
  for (auto it = fs::directory_iterator(suite, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const auto ext = it->path().extension();
    if (ext != ".yaml" && ext != ".yml") continue;
    std::error_code fe;
    if (!it->is_regular_file(fe))  // a dangling link, a FIFO, a device or a folder named *.yaml
      throw models::SceneError(it->path().string(), 0, "--suite", "not a readable scene file (a link to nothing, a FIFO, a "
                                                                  "device or a folder); remove it or rename it");
    files.push_back(it->path().string());
    if (files.size() > kMaxSuiteScenes)
      throw models::SceneError(suite, 0, "--suite", fmt::format("more than {} scenes", kMaxSuiteScenes));
  }
  if (ec) throw models::SceneError(suite, 0, "--suite", "cannot list the folder: " + ec.message());
  std::sort(files.begin(), files.end());
  if (files.empty()) throw models::SceneError(suite, 0, "--suite", "the folder has no .yaml scenes");
  std::map<std::string, std::string> seen;
  for (const auto& f : files) {
    const std::string stem = fs::path(f).stem().string();
    if (!plain_name(stem))
      throw models::SceneError(f, 0, "--suite",
                               "the file name must be a plain name (letters, digits, '_', '-', '.'; not starting with "
                               "'.' or '-'; at most 64 characters): it names the scene's report folder");
    if (stem == "summary.json" || stem == "index.html")
      throw models::SceneError(f, 0, "--suite", "the name '" + stem + "' is the suite's own output file; rename the scene");
    if (seen.count(stem))
      throw models::SceneError(f, 0, "--suite", "has the same name as " + seen[stem] + " (both would write " + stem + "/)");
    seen[stem] = f;
  }
  return files;
}

int run_suite(const ValidateArgs& a, Progress& progress) {
  namespace fs = std::filesystem;
  const auto files = suite_files(a.suite);
  const auto overrides = overrides_of(a.sets);  // a malformed --set is the user's error (exit 2), not a scene's
  OutputDir out(a.out, a.force);
  ValidationOptions opt;
  opt.quick = !a.thorough;
  opt.peers = a.peers;
  nlohmann::json scenes = nlohmann::json::array();
  bool all_pass = true;
  std::string rows;
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string stem = fs::path(files[i]).stem().string();
    progress.note(fmt::format("[{}/{}] {}", i + 1, files.size(), files[i]));
    const auto started = std::chrono::steady_clock::now();
    nlohmann::json entry;
    try {
      const auto scene = models::load_scene(files[i], overrides);
      out.make_subfolder(stem);
      bool pass = false;
      entry = validate_one(scene, opt, out.file(stem), progress, pass);
      all_pass &= pass;
    } catch (const OutputError&) {
      throw;  // the output itself failed: nothing is written
    } catch (const std::exception& e) {  // a failing scene does not stop the others
      entry = {{"name", stem}, {"file", files[i]}, {"status", "error"}, {"error", e.what()}};
      all_pass = false;
    }
    // A scene that failed before its report was written (it did not load or assemble) has none
    // to link to: its row says why instead.
    if (fs::exists(fs::path(out.file(stem)) / "report.html")) entry["report"] = stem + "/report.html";
    // One line a scene whatever standard error is (a suite runs for minutes, often into a log):
    // the progress above is drawn on a terminal only.
    std::fprintf(stderr, "rdyn: suite [%zu/%zu] %s: %s (%.0f s)\n", i + 1, files.size(), stem.c_str(),
                 entry.value("status", std::string("?")).c_str(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    rows += suite_row(stem, entry);
    scenes.push_back(entry);
  }
  write_json(out.file("summary.json"),
             {{"suite", a.suite}, {"status", all_pass ? "pass" : "fail"}, {"scenes", scenes}});
  write_text_file(out.file("index.html"),
                  "<!DOCTYPE html><html><head><meta charset='utf-8'><title>rdyn suite</title><style>body{font-family:"
                  "sans-serif;max-width:1000px;margin:2em auto}td,th{border:1px solid #ccc;padding:3px 6px}table{"
                  "border-collapse:collapse}.pass{color:#070}.fail,.error{color:#a00}</style></head><body><h1>rdyn "
                  "validation suite: " + html_escape(a.suite) + "</h1><table><tr><th>scene</th><th>status</th>"
                  "<th>verdicts (error, limit)</th><th>recommended setting vs full run at equal or better error</th><th>what it tests / error</th></tr>" +
                  rows + "</table></body></html>\n");
  out.commit();
  std::fprintf(stderr, "rdyn: suite %s: %s; wrote %s/index.html\n", a.suite.c_str(),
               all_pass ? "all scenes pass" : "FAILURES", a.out.c_str());
  return all_pass ? 0 : 1;
}

}  // namespace

// Largest summary.json `rdyn report` reads (the bicycle's full ladder writes ~0.7 MB).
constexpr std::uintmax_t kMaxSummaryBytes = 64u << 20;

int run_report(const ReportArgs& a) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (const std::string kind = models::non_regular_file_kind(a.summary); !kind.empty())  // before opening
    throw ArgumentError(a.summary + ": not a regular file (" + kind + "): give the summary.json of `rdyn validate`");
  if (!fs::is_regular_file(a.summary, ec))
    throw ArgumentError(a.summary + ": not a readable file (give the summary.json of `rdyn validate`)");
  const auto size = fs::file_size(a.summary, ec);
  if (ec || size > kMaxSummaryBytes)
    throw ArgumentError(fmt::format("{}: larger than {} MB, not a summary of `rdyn validate`", a.summary,
                                    kMaxSummaryBytes >> 20));
  std::ifstream in(a.summary, std::ios::binary);
  nlohmann::json summary;
  try {
    summary = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw ArgumentError(fmt::format("{}: not valid JSON ({})", a.summary, e.what()));
  }
  if (!summary.is_object() || !summary.contains("scene") || !summary.contains("runs"))
    throw ArgumentError(a.summary + ": not a summary of `rdyn validate` (no 'scene' and 'runs')");
  if (const std::string bad = report_format::find_non_number(summary); !bad.empty())
    throw ArgumentError(fmt::format("{}: field {} (not what rdyn validate writes there)", a.summary, bad));
  if (const std::string bad = report_format::find_malformed_record(summary); !bad.empty())
    throw ArgumentError(fmt::format("{}: field {} (not what rdyn validate writes there)", a.summary, bad));
  OutputDir out(a.out, a.force);
  try {
    render_report(summary, out.file(""));
  } catch (const nlohmann::json::exception& e) {
    // A hand-edited summary: a key missing or of the wrong type.
    throw ArgumentError(fmt::format("{}: not a summary of `rdyn validate` ({})", a.summary, e.what()));
  } catch (const models::SceneError& e) {  // its animation's scene does not read
    throw ArgumentError(fmt::format("{}: not a summary of `rdyn validate` ({})", a.summary, e.what()));
  } catch (const std::invalid_argument& e) {  // its animation's frames are not one pose per frame
    throw ArgumentError(fmt::format("{}: not a summary of `rdyn validate` ({})", a.summary, e.what()));
  }
  out.commit();
  std::fprintf(stderr, "rdyn: re-rendered %s into %s/report.html\n", a.summary.c_str(), a.out.c_str());
  return 0;
}

int run_validate(const ValidateArgs& a) {
  if (!a.suite.empty() && !a.scene.empty()) throw ArgumentError("give a scene or --suite, not both");
  if (a.suite.empty() && a.scene.empty()) throw ArgumentError("give a scene or --suite FOLDER");
  if (a.quick && a.thorough) throw ArgumentError("--quick and --thorough: give one of them");
  check_peers(a.peers);  // before any work: a peer this build cannot run is exit 2
  Progress progress;
  if (!a.suite.empty()) return run_suite(a, progress);
  const auto scene = load(a.scene, a.sets);
  const nlohmann::json summary = validate_scene(scene, a, progress);
  const bool pass = summary.value("status", std::string()) == "pass";
  std::printf("%s\n\nReport: %s/report.html\n", headline(summary).c_str(), a.out.c_str());
  if (!pass) {
    std::string why;
    for (const auto& f : summary.value("failures", nlohmann::json::array()))
      why += (why.empty() ? "" : "; ") + f.get<std::string>();
    std::fprintf(stderr, "rdyn: validation of %s FAILED: %s\n", scene.name.c_str(), why.c_str());
  }
  return pass ? 0 : 1;
}

nlohmann::json validate_scene(const models::Scene& scene, const ValidateArgs& a, Progress& progress) {
  check_peers(a.peers);  // before any work: a peer this build cannot run is exit 2
  if (a.quick && a.thorough) throw ArgumentError("--quick and --thorough: give one of them");
  OutputDir out(a.out, a.force);
  ValidationOptions opt;
  opt.quick = a.quick;
  opt.peers = a.peers;
  const ValidationResult v = run_validation(scene, opt, progress);
  nlohmann::json summary = with_drawing(summary_json(v), scene, v);
  render_report(summary, out.file(""));
  out.commit();
  return summary;
}

}  // namespace rdyn::validate
