#include "validate/report/cycle_animation.hpp"

#include <stdexcept>

#include <fmt/format.h>

#include "models/scene_write.hpp"
#include "models/scene_yaml.hpp"
#include "validate/io/escape.hpp"

namespace rdyn::validate {

nlohmann::json animation_record(const models::Scene& scene, const CycleStart& start, const models::TimeSeries& cycle,
                                const std::string& title) {
  const MechanismFrames f = frames_from_run(scene, cycle, {});
  nlohmann::json arrows = nlohmann::json::array();
  for (const auto& a : f.arrows)
    arrows.push_back({{"name", a.name}, {"body", a.body}, {"point", {a.point.x, a.point.y}}, {"fx_N", a.fx_N},
                      {"fy_N", a.fy_N}});
  return {{"title", title},
          {"scene_yaml", models::scene_to_yaml(scene)},
          {"start",
           {{"t_s", start.t_s},
            {"q", start.q},
            {"qdot", start.qdot},
            {"duration_s", start.duration_s},
            {"revolution", start.revolution}}},
          {"frames",
           {{"t_s", f.t_s}, {"q", f.q}, {"q_joint", f.q_joint}, {"arrows", arrows}, {"traces", f.traces}}}};
}

AnimationRecord read_animation_record(const nlohmann::json& r) {
  AnimationRecord a;
  a.title = r.at("title").get<std::string>();
  a.scene = models::parse_scene(r.at("scene_yaml").get<std::string>(), "summary.json (animation)");
  const auto& st = r.at("start");
  a.start = {st.at("t_s").get<double>(), st.at("q").get<double>(), st.at("qdot").get<double>(),
             st.at("duration_s").get<double>(), st.value("revolution", true)};
  const auto& f = r.at("frames");
  a.frames.t_s = f.at("t_s").get<std::vector<double>>();
  a.frames.q = f.at("q").get<std::vector<double>>();
  a.frames.q_joint = f.at("q_joint").get<std::vector<std::vector<double>>>();
  for (const auto& qj : a.frames.q_joint)
    if (qj.size() != a.scene.joints.size())
      throw std::invalid_argument("summary.json (animation): a frame without one coordinate per joint");
  for (const auto& ar : f.at("arrows")) {
    const auto p = ar.at("point").get<std::vector<double>>();
    if (p.size() != 2) throw std::invalid_argument("summary.json (animation): an arrow's point is not [x, y]");
    a.frames.arrows.push_back({ar.at("name").get<std::string>(), ar.at("body").get<std::string>(), {p[0], p[1]},
                               ar.at("fx_N").get<std::vector<double>>(), ar.at("fy_N").get<std::vector<double>>()});
  }
  a.frames.traces = f.at("traces").get<std::vector<std::string>>();
  return a;
}

std::string animation_record_html(const nlohmann::json& record) {
  const AnimationRecord a = read_animation_record(record);
  return "<style>" + animation_css() + "</style>\n" + animation_section(a.scene, a.frames, a.title);
}

std::string mechanism_drawing_html(const nlohmann::json& summary) {
  if (!summary.contains("mechanism_svg") || !summary.at("mechanism_svg").is_string()) return "";
  return "<h2>The mechanism</h2><p><img alt=\"the mechanism at its assembled configuration\" "
         "style=\"max-width:100%;max-height:60vh\" src=\"data:image/svg+xml;base64," +
         base64(summary.at("mechanism_svg").get<std::string>()) +
         "\"></p><p>The assembled configuration (<code>rdyn inspect SCENE --svg FILE</code>; "
         "<code>rdyn animate SCENE</code> plays a run).</p>\n";
}

std::string validate_animation_html(const nlohmann::json& summary) {
  if (summary.contains("animation_error") && summary.at("animation_error").is_string())
    return "<h2>The mechanism in motion</h2><p class=warn>Not animated: " +
           html_escape(summary.at("animation_error").get<std::string>()) + "</p>\n";
  if (!summary.contains("animation")) return "";
  const auto& st = summary.at("animation").at("start");
  const double t0 = st.at("t_s").get<double>(), d = st.at("duration_s").get<double>();
  // A coordinate that does not turn (a rocker, a slider) has no cycles to speak of: its last stretch.
  const std::string head =
      st.value("revolution", true)
          ? fmt::format("<h2>The mechanism over one steady cycle</h2><p>The reference's last whole revolution, "
                        "from t = {:.4g} s for {:.4g} s",
                        t0, d)
          : fmt::format("<h2>The mechanism over the end of the run</h2><p>The reference's last {:.4g} s (the "
                        "scene's time scale), from t = {:.4g} s",
                        d, t0);
  return head +
         ": the full model (Simbody) restarted from the reference's state there, every position placed from the "
         "joint coordinates it outputs. <code>report.html#t=T</code> shows the frame nearest T.</p>\n" +
         animation_record_html(summary.at("animation"));
}

std::string strategies_animation_html(const nlohmann::json& summary) {
  if (!summary.contains("animations")) return "";
  const auto& an = summary.at("animations");
  return "<h2>The two strategies over one steady cycle</h2><p>Each strategy's full model (Simbody) from its steady "
         "point, over one period at its full-model cadence; the arrows are the scene's requested constraint "
         "forces. "
         "<code>report.html#t=T</code> shows the frame nearest T in both.</p>\n"
         "<div class=\"strategies\" style=\"display:flex;gap:1em;flex-wrap:wrap\">"
         "<div data-strategy=\"constant\" style=\"flex:1 1 420px;min-width:0\">" +
         animation_record_html(an.at("constant")) +
         "</div><div data-strategy=\"optimised\" style=\"flex:1 1 420px;min-width:0\">" +
         animation_record_html(an.at("optimised")) + "</div></div>\n";
}

}  // namespace rdyn::validate
