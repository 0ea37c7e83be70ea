#include "validate/cli/inspect.hpp"

#include "models/gear_fold.hpp"

#include <cstdio>

#include <fmt/format.h>

#include <memory>

#include "models/scene_yaml.hpp"
#include "validate/cli/animate_command.hpp"
#include "validate/io/output_dir.hpp"

namespace rdyn::validate {

namespace {
constexpr double kDeg = 180.0 / 3.14159265358979323846;
}

nlohmann::json assembly_json(const engine::Inspection& a) {
  nlohmann::json joints = nlohmann::json::object();
  for (const auto& j : a.joints)
    joints[j.name] = j.revolute ? nlohmann::json{{"q_deg", j.q * kDeg}} : nlohmann::json{{"q_m", j.q}};
  return joints;
}

// The range in words (engine::describe_domain), and for a full turn what the gears allow: a joint
// geared at 1:2 comes back only after two turns of q, and when its angle matters (a loop, an
// off-axis mass) no table over one turn describes the mechanism (a five-bar driven from its fast
// crank: inspect said "full turn" and extract blamed the grid).
std::string range_reason(const models::Scene& scene, const engine::IndependentDomain& d) {
  std::string reason = engine::describe_domain(d, scene.independent);
  std::string why;
  const int turns = d.periodic ? models::calc_turns_to_repeat(scene, why) : 1;
  if (turns != 1)
    reason += fmt::format("; but {}: where that joint's angle matters (a loop, an off-axis mass) the mechanism {}, "
                          "and a table over one turn cannot describe it (make the joint that turns the fewest times "
                          "the independent coordinate)",
                          why, turns > 1 ? fmt::format("repeats only every {} turns", turns) : "never repeats");
  return reason;
}

nlohmann::json inspection_json(const models::Scene& scene, const engine::Inspection& in) {
  nlohmann::json joints = nlohmann::json::object();
  for (const auto& j : in.joints) {
    joints[j.name] = j.revolute ? nlohmann::json{{"q_deg", j.q * kDeg}, {"guess_deg", j.guess * kDeg}}
                                : nlohmann::json{{"q_m", j.q}, {"guess_m", j.guess}};
  }
  nlohmann::json bodies = nlohmann::json::object();
  for (const auto& b : in.bodies)
    bodies[b.name] = {{"x_m", b.x_m}, {"y_m", b.y_m}, {"angle_deg", b.angle_rad * kDeg},
                      {"com_m", {b.com_x_m, b.com_y_m}}};
  nlohmann::json loops = nlohmann::json::object();
  for (const auto& l : in.loops) loops[l.name] = {{"gap_m", l.gap_m}};
  const bool rev = scene.find_joint(scene.independent)->type == models::JointType::Revolute;
  const double k = rev ? kDeg : 1.0;
  const std::string unit = rev ? "deg" : "m";
  // The domain the models use (engine/independent_range.hpp); edges named as the range tables
  // name them (`edges=dead_point,declared_limit`, docs/theory.md "Range tables").
  const auto& d = in.range;
  auto edge = [](std::string e) {
    for (char& ch : e)
      if (ch == ' ') ch = '_';
    return e;
  };
  nlohmann::json range = {{"joint", scene.independent}, {"unit", unit}, {"full_turn", d.periodic}};
  if (!d.unbounded_reason.empty()) {
    range["unbounded_reason"] = d.unbounded_reason;  // no finite edges: min/max left out
  } else if (!d.periodic) {
    range["min"] = d.min * k;
    range["max"] = d.max * k;
    range["min_edge"] = edge(d.min_edge);
    range["max_edge"] = edge(d.max_edge);
    range["min_is_dead_point"] = d.min_edge == "dead point";
    range["max_is_dead_point"] = d.max_edge == "dead point";
  }
  nlohmann::json dead = nlohmann::json::array();
  if (d.dead_min && d.dead_max) {
    dead = {*d.dead_min * k, *d.dead_max * k};
    range["dead_point_margin"] = engine::kDeadPointMargin;               // of the dead points' distance
    range["margin"] = engine::calc_dead_point_margin(d) * k;              // the same in deg or m
  }
  range["dead_points"] = dead;
  // Why: full turn, declared by the scene, dead points found (and the margin), or unbounded.
  range["reason"] = range_reason(scene, d);
  // Gears that need k turns of q to bring every joint back (0: never; models/gear_fold.hpp).
  std::string gears_why;
  range["turns_to_repeat"] = models::calc_turns_to_repeat(scene, gears_why);
  // Configurations of rank loss inside the domain (a parallelogram lying flat): passable, not
  // edges; the full model crosses them in its partitioned formulation (docs/theory.md §7a).
  nlohmann::json singular = nlohmann::json::array();
  for (const auto& p : d.singular) singular.push_back(p.q * k);
  range["singular_configurations"] = singular;
  return {{"scene", scene.name},
          {"scene_file", scene.source_file},
          {"independent", scene.independent},
          {"initial", rev ? nlohmann::json{{"q_deg", scene.initial.q * kDeg}, {"qdot", scene.initial.qdot}}
                          : nlohmann::json{{"q_m", scene.initial.q}, {"qdot", scene.initial.qdot}}},
          {"degrees_of_freedom",
           {{"value", in.mobility.mobilities - in.mobility.rank},
            {"joint_coordinates", in.mobility.mobilities},
            {"constraint_rows", in.mobility.rows},
            {"constraint_jacobian_rank", in.mobility.rank}}},
          {"joints", joints},
          {"bodies", bodies},
          {"loops", loops},
          {"range", range},
          {"length_scale_m", in.length_scale_m},
          {"warnings", in.warnings}};
}

int run_inspect(const InspectArgs& a) {
  std::vector<models::Override> overrides;
  for (const auto& s : a.sets) overrides.push_back(models::parse_override(s));
  const models::Scene scene = models::load_scene(a.scene, overrides);
  // The drawing's destination is checked before any work.
  std::unique_ptr<OutputFile> svg;
  if (!a.svg.empty()) svg = std::make_unique<OutputFile>(a.svg, a.force, is_rdyn_svg);
  const engine::FullModel model(scene);
  const auto in = engine::calc_inspection(model);
  for (const auto& w : in.warnings) std::fprintf(stderr, "rdyn: warning: %s\n", w.c_str());
  // The range in words (standard output stays JSON): the same sentence as range.reason.
  if (in.range.unbounded_reason.empty())
    std::fprintf(stderr, "rdyn: range of '%s': %s\n", scene.independent.c_str(),
                 range_reason(scene, in.range).c_str());
  if (svg) {
    svg->write(inspect_svg(scene, in));
    svg->commit();
  }
  const std::string text = inspection_json(scene, in).dump(2) + "\n";
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace rdyn::validate
