// The mechanism in the validate and optimize reports: the assembled drawing, and the animation
// of one steady cycle: its record in
// summary.json (the scene as rdyn reads it, where the cycle started, and the frames — every
// joint's coordinate and the requested forces per frame, from analysis/cycle_run.hpp's run) and
// the HTML drawn from that record alone (validate/report/mechanism_drawing.hpp), so `rdyn report`
// redraws it without simulating. Every position on the page comes from models::calc_pose on the
// recorded joint coordinates.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "models/scene.hpp"
#include "models/timeseries.hpp"
#include "validate/analysis/cycle_run.hpp"
#include "validate/report/mechanism_drawing.hpp"

namespace rdyn::validate {

// {"title", "scene_yaml", "start": {t_s, q, qdot, duration_s}, "frames": {t_s, q, q_joint,
// arrows: [{name, body, point, fx_N, fy_N}], traces}} from a cycle run (simulate_cycle; at most
// kMaxFrames rows are kept, as rdyn animate does).
nlohmann::json animation_record(const models::Scene& scene, const CycleStart& start, const models::TimeSeries& cycle,
                                const std::string& title);

struct AnimationRecord {
  models::Scene scene;
  CycleStart start;
  MechanismFrames frames;
  std::string title;
};
// Reads a record back (`path`: where it sits in summary.json, for messages). Throws
// std::invalid_argument naming the JSON path of a missing key, a wrong type or frames of the
// wrong sizes, models::SceneError for a scene that does not read.
AnimationRecord read_animation_record(const nlohmann::json& record, const std::string& path = "animation");

// The record's animation (mechanism_drawing.hpp's animation_section, with its style), under its
// title.
std::string animation_record_html(const nlohmann::json& record, const std::string& path = "animation");

// The assembled mechanism (summary["mechanism_svg"], `inspect --svg`'s drawing) as an image from a
// data: URI — a summary.json edited by hand cannot run script through it; "" when there is none.
std::string mechanism_drawing_html(const nlohmann::json& summary);

// The validate report's section: summary["animation"] under a heading with a sentence saying what
// it shows; "" when the summary has none.
std::string validate_animation_html(const nlohmann::json& summary);

// The optimize report's section: summary["animations"]["constant"] and ["optimised"] side by side
// (each with its own controls; `#t=T` moves both); "" when the summary has none.
std::string strategies_animation_html(const nlohmann::json& summary);

}  // namespace rdyn::validate
