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

namespace {

// A field of a record in a summary.json (perhaps edited by hand), named by its JSON path when it
// is missing or not of the type rdyn writes there.
const nlohmann::json& field(const nlohmann::json& j, const std::string& key, const std::string& path) {
  if (!j.is_object() || !j.contains(key)) throw std::invalid_argument("summary.json: " + path + "." + key + " is missing");
  return j.at(key);
}

template <class T>
T field_as(const nlohmann::json& j, const std::string& key, const std::string& path) {
  try {
    return field(j, key, path).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw std::invalid_argument("summary.json: " + path + "." + key + " is not of the type rdyn writes there");
  }
}

}  // namespace

AnimationRecord read_animation_record(const nlohmann::json& r, const std::string& path) {
  AnimationRecord a;
  a.title = field_as<std::string>(r, "title", path);
  a.scene = models::parse_scene(field_as<std::string>(r, "scene_yaml", path), "summary.json (" + path + ")");
  const auto& st = field(r, "start", path);
  const std::string sp = path + ".start";
  a.start = {field_as<double>(st, "t_s", sp), field_as<double>(st, "q", sp), field_as<double>(st, "qdot", sp),
             field_as<double>(st, "duration_s", sp), st.contains("revolution") ? field_as<bool>(st, "revolution", sp) : true};
  const auto& f = field(r, "frames", path);
  const std::string fp = path + ".frames";
  a.frames.t_s = field_as<std::vector<double>>(f, "t_s", fp);
  a.frames.q = field_as<std::vector<double>>(f, "q", fp);
  a.frames.q_joint = field_as<std::vector<std::vector<double>>>(f, "q_joint", fp);
  for (const auto& qj : a.frames.q_joint)
    if (qj.size() != a.scene.joints.size())
      throw std::invalid_argument("summary.json: " + fp + ".q_joint: a frame without one coordinate per joint");
  const auto& arrows = field(f, "arrows", fp);
  if (!arrows.is_array()) throw std::invalid_argument("summary.json: " + fp + ".arrows is not a list");
  for (size_t i = 0; i < arrows.size(); ++i) {
    const auto& ar = arrows[i];
    const std::string ap = fmt::format("{}.arrows[{}]", fp, i);
    const auto p = field_as<std::vector<double>>(ar, "point", ap);
    if (p.size() != 2) throw std::invalid_argument("summary.json: " + ap + ".point is not [x, y]");
    a.frames.arrows.push_back({field_as<std::string>(ar, "name", ap), field_as<std::string>(ar, "body", ap),
                               {p[0], p[1]}, field_as<std::vector<double>>(ar, "fx_N", ap),
                               field_as<std::vector<double>>(ar, "fy_N", ap)});
  }
  a.frames.traces = field_as<std::vector<std::string>>(f, "traces", fp);
  return a;
}

namespace {

std::string record_html(const AnimationRecord& a) {
  return "<style>" + animation_css() + "</style>\n" + animation_section(a.scene, a.frames, a.title);
}

}  // namespace

std::string animation_record_html(const nlohmann::json& record, const std::string& path) {
  return record_html(read_animation_record(record, path));
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
  const AnimationRecord a = read_animation_record(summary.at("animation"), "animation");
  const double t0 = a.start.t_s, d = a.start.duration_s;
  // A coordinate that does not turn (a rocker, a slider) has no cycles to speak of: its last stretch.
  const std::string head =
      a.start.revolution
          ? fmt::format("<h2>The mechanism over one steady cycle</h2><p>The reference's last whole revolution, "
                        "from t = {:.4g} s for {:.4g} s",
                        t0, d)
          : fmt::format("<h2>The mechanism over the end of the run</h2><p>The reference's last {:.4g} s (the "
                        "scene's time scale), from t = {:.4g} s",
                        d, t0);
  return head +
         ": the full model (Simbody) restarted from the reference's state there, every position placed from the "
         "joint coordinates it outputs. <code>report.html#t=T</code> shows the frame nearest T.</p>\n" +
         record_html(a);
}

std::string strategies_animation_html(const nlohmann::json& summary) {
  if (!summary.contains("animations")) return "";
  const auto& an = summary.at("animations");
  if (!an.is_object()) throw std::invalid_argument("summary.json: animations is not an object");
  return "<h2>The two strategies over one steady cycle</h2><p>Each strategy's full model (Simbody) from its steady "
         "point, over one period at its full-model cadence; the arrows are the scene's requested constraint "
         "forces. "
         "<code>report.html#t=T</code> shows the frame nearest T in both.</p>\n"
         "<div class=\"strategies\" style=\"display:flex;gap:1em;flex-wrap:wrap\">"
         "<div data-strategy=\"constant\" style=\"flex:1 1 420px;min-width:0\">" +
         animation_record_html(field(an, "constant", "animations"), "animations.constant") +
         "</div><div data-strategy=\"optimised\" style=\"flex:1 1 420px;min-width:0\">" +
         animation_record_html(field(an, "optimised", "animations"), "animations.optimised") + "</div></div>\n";
}

}  // namespace rdyn::validate
