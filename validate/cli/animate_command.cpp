#include "validate/cli/animate_command.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "engine/full_model.hpp"
#include "engine/inspect.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/mechanism_run.hpp"
#include "validate/cli/cli_limits.hpp"
#include "validate/io/argument_error.hpp"
#include "validate/io/output_dir.hpp"
#include "validate/report/mechanism_drawing.hpp"

namespace rdyn::validate {

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;

models::Scene load(const std::string& scene, const std::vector<std::string>& sets) {
  std::vector<models::Override> overrides;
  for (const auto& s : sets) overrides.push_back(models::parse_override(s));
  return models::load_scene(scene, overrides);
}

// A trace names a body and one of its named points: checked before any work.
void check_traces(const models::Scene& s, const std::vector<std::string>& traces) {
  for (size_t i = 0; i < traces.size(); ++i) {
    const std::string& t = traces[i];
    const auto dot = t.find('.');
    const auto* b = dot == std::string::npos ? nullptr : s.find_body(t.substr(0, dot));
    if (!b || !b->points.count(t.substr(dot + 1)))
      throw ArgumentError(fmt::format("--trace (the {}. one): not BODY.POINT naming a body of the scene and one of "
                                      "its named points",
                                      i + 1));
  }
}

// The independent coordinate's domain in words, as inspect's JSON gives it.
std::string range_note(const models::Scene& s, const engine::Inspection& in) {
  const bool rev = s.find_joint(s.independent)->type == models::JointType::Revolute;
  const double k = rev ? kDeg : 1.0;
  const char* unit = rev ? "°" : " m";
  const auto& d = in.range;
  std::string note = "independent " + s.independent + ": ";
  if (d.periodic) return note + "turns fully";
  if (!d.unbounded_reason.empty()) return note + "unbounded (" + d.unbounded_reason + ")";
  note += fmt::format("range [{:.4g}{}, {:.4g}{}] ({}, {})", d.min * k, unit, d.max * k, unit, d.min_edge, d.max_edge);
  if (d.dead_min && d.dead_max)
    note += fmt::format("; dead points at {:.4g}{} and {:.4g}{}", *d.dead_min * k, unit, *d.dead_max * k, unit);
  return note;
}

}  // namespace

int run_animate(const AnimateArgs& a) {
  const models::Scene scene = load(a.scene, a.sets);
  const double duration = a.duration.value_or(scene.simulation.duration_s);
  const double dt_out = a.dt_out.value_or(scene.simulation.output_interval_s);
  if (!(std::isfinite(duration) && duration > 0 && duration <= cli_limits::kMaxDuration_s))
    throw ArgumentError(fmt::format("--duration: must be a finite number in (0, {:g}] s (got {})",
                                    cli_limits::kMaxDuration_s, duration));
  if (!(std::isfinite(dt_out) && dt_out >= cli_limits::kMinOutputInterval_s && dt_out <= duration))
    throw ArgumentError(fmt::format("--dt-out: must be a finite number in [{:g} s, --duration] (got {})",
                                    cli_limits::kMinOutputInterval_s, dt_out));
  // Frames are capped (kMaxFrames) but the run's rows are held in memory first: bound them.
  if (duration / dt_out > 1e6)
    throw ArgumentError(fmt::format("--dt-out: {:g} s over {:g} s makes more than 1e6 rows", dt_out, duration));
  check_traces(scene, a.traces);
  OutputDir out(a.out, a.force);  // fails early on an unusable folder
  const auto ts = simulate_every_joint(scene, a.model, duration, dt_out);
  const auto frames = frames_from_run(scene, ts, a.traces);
  const std::string title = fmt::format("{} — {} model, {:g} s", scene.name, a.model, duration);
  write_text_file(out.file("animation.html"), animation_html(scene, frames, title));
  out.commit();
  std::fprintf(stderr, "rdyn: %s: %zu frames; wrote %s/animation.html\n", scene.name.c_str(), frames.t_s.size(),
               a.out.c_str());
  return 0;
}

bool is_rdyn_svg(const std::string& head) {
  return head.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"mechanism\"", 0) == 0;
}

std::string inspect_svg(const models::Scene& scene, const engine::Inspection& in) {
  MechanismFrames f;
  f.t_s = {0.0};
  f.q = {scene.initial.q};
  std::vector<double> qj;
  for (const auto& j : in.joints) qj.push_back(j.q);  // scene.joints order (engine/inspect.hpp)
  f.q_joint = {qj};
  return mechanism_svg(scene, f, 0, range_note(scene, in));
}

}  // namespace rdyn::validate
