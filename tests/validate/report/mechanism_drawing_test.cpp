// The drawing against Simbody's own body frames: at the assembled configuration every joint
// element's data-x/data-y must be the joint point placed by the body transform the full model
// reports (engine::calc_assembly), a route that shares nothing with models::calc_pose.
#include "validate/report/mechanism_drawing.hpp"

#include <cmath>
#include <map>
#include <regex>

#include <gtest/gtest.h>

#include "engine/full_model.hpp"
#include "engine/inspect.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::validate {
namespace {

// Each element carrying `attr`="name": its data-x, data-y.
std::map<std::string, std::pair<double, double>> positions(const std::string& svg, const std::string& attr) {
  std::map<std::string, std::pair<double, double>> out;
  const std::regex el("<[a-z]+ " + attr + "=\"([^\"]+)\"[^>]*>");
  const std::regex x("data-x=\"([^\"]+)\""), y("data-y=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), el); it != std::sregex_iterator(); ++it) {
    const std::string tag = (*it)[0];
    std::smatch mx, my;
    if (std::regex_search(tag, mx, x) && std::regex_search(tag, my, y))
      out[(*it)[1]] = {std::stod(mx[1]), std::stod(my[1])};
  }
  return out;
}

MechanismFrames assembled(const models::Scene& s, const engine::Inspection& in) {
  MechanismFrames f;
  f.t_s = {0};
  f.q = {s.initial.q};
  std::vector<double> q;
  for (const auto& j : in.joints) q.push_back(j.q);
  f.q_joint = {q};
  return f;
}

void expect_joints_on_simbody_frames(const std::string& scene) {
  const auto s = models::load_scene(scene, {});
  const auto in = engine::calc_assembly(engine::FullModel(s));
  const std::string svg = mechanism_svg(s, assembled(s, in), 0, "note <&>");
  const auto joints = positions(svg, "data-joint");
  ASSERT_EQ(joints.size(), s.joints.size()) << scene;
  for (const auto& j : s.joints) {
    const auto* b = &in.bodies[s.body_index(j.child)];
    ASSERT_EQ(b->name, j.child);
    const double c = std::cos(b->angle_rad), si = std::sin(b->angle_rad);
    const double x = b->x_m + c * j.child_point.x - si * j.child_point.y;
    const double y = b->y_m + si * j.child_point.x + c * j.child_point.y;
    EXPECT_NEAR(joints.at(j.name).first, x, 1e-12) << scene << " " << j.name;
    EXPECT_NEAR(joints.at(j.name).second, y, 1e-12) << scene << " " << j.name;
  }
  for (const auto& b : s.bodies) EXPECT_NE(svg.find("data-body=\"" + b.name + "\""), std::string::npos) << b.name;
  EXPECT_NE(svg.find("note &lt;&amp;&gt;"), std::string::npos);  // the note is escaped
}

TEST(MechanismDrawing, JointsSitWhereSimbodyPutsTheBodies) {
  expect_joints_on_simbody_frames("fourbar");
  expect_joints_on_simbody_frames("bicycle");
  expect_joints_on_simbody_frames("crane-luffing");
  expect_joints_on_simbody_frames(std::string(RDYN_SCENES) + "/chains/chain-3.yaml");
}

TEST(MechanismDrawing, GroundPivotsAreTheGroundPoints) {
  const auto s = models::load_scene("fourbar", {});
  const auto in = engine::calc_assembly(engine::FullModel(s));
  const auto piv = positions(mechanism_svg(s, assembled(s, in), 0, ""), "data-ground-pivot");
  size_t n = 0;
  for (const auto& j : s.joints)
    if (j.parent == models::kGround) {
      ++n;
      EXPECT_EQ(piv.at(j.name).first, j.parent_point.x);
      EXPECT_EQ(piv.at(j.name).second, j.parent_point.y);
    }
  EXPECT_EQ(piv.size(), n);
}

TEST(MechanismDrawing, FramesAreBoundedAndKeepTheEnds) {
  const auto s = models::load_scene("fourbar", {});
  models::TimeSeries ts;
  const size_t n = 4999;
  for (size_t i = 0; i < n; ++i) {
    ts.t.push_back(0.001 * i);
    ts.q.push_back(0.01 * i);
  }
  for (const auto& j : s.joints) {
    ts.column_names.push_back("q_" + j.name);
    ts.columns.push_back(ts.q);
  }
  const auto f = frames_from_run(s, ts, {}, 2000);
  EXPECT_LE(f.t_s.size(), 2000u);
  EXPECT_GE(f.t_s.size(), 1000u);
  EXPECT_EQ(f.t_s.front(), 0.0);
  EXPECT_EQ(f.t_s.back(), ts.t.back());
  EXPECT_THROW(mechanism_svg(s, frames_from_run(s, ts, {"crank.nowhere"}, 2000), 0, ""), std::invalid_argument);
}

TEST(MechanismDrawing, PageIsSelfContainedAndEscaped) {
  const auto s = models::load_scene("fourbar", {});
  const auto in = engine::calc_assembly(engine::FullModel(s));
  const std::string html = animation_html(s, assembled(s, in), "a </script><b>title");
  EXPECT_NE(html.find("a &lt;/script&gt;&lt;b&gt;title"), std::string::npos);
  EXPECT_EQ(html.find("http://", html.find("</svg>")), std::string::npos);  // nothing fetched
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_NE(html.find("<script class=\"frames\" type=\"application/json\">"), std::string::npos);
  MechanismFrames bad = assembled(s, in);
  bad.t_s.push_back(0);  // sizes differ
  EXPECT_THROW(animation_html(s, bad, ""), std::invalid_argument);
}

// An arrow's label sits just beyond its head, on the side the force points to (the head does not
// hide its first letters): anchored at its start to the right, at its end to the left, hanging
// below a head that points down.
TEST(MechanismDrawing, ArrowLabelsSitBeyondTheHead) {
  const auto s = models::load_scene("fourbar", {});
  const auto in = engine::calc_assembly(engine::FullModel(s));
  MechanismFrames f = assembled(s, in);
  f.t_s.push_back(1), f.q.push_back(f.q[0]), f.q_joint.push_back(f.q_joint[0]);
  f.arrows = {ForceArrow{"F", "crank", s.find_body("crank")->points.at("B"), {10.0, -10.0}, {2.0, -2.0}}};
  for (size_t k = 0; k < 2; ++k) {
    const std::string svg = mechanism_svg(s, f, k, "");
    std::smatch line, text;
    ASSERT_TRUE(std::regex_search(svg, line, std::regex("data-arrow=\"0\"[^>]* x2=\"([^\"]+)\"")));
    ASSERT_TRUE(std::regex_search(
        svg, text,
        std::regex("data-arrow-label=\"0\"[^>]* x=\"([^\"]+)\"[^>]* text-anchor=\"([a-z]+)\" dominant-baseline=\"([a-z]+)\"")));
    const double tip = std::stod(line[1]), at = std::stod(text[1]);
    // The drawing has room for the label: its left end (0.6 em a character, the font 3 % of the
    // drawing's size) inside the viewBox, also for the arrow pointing left out of the mechanism.
    std::smatch vb, fs;
    ASSERT_TRUE(std::regex_search(svg, vb, std::regex("viewBox=\"([^ ]+) ([^ ]+) ([^ ]+) ")));
    ASSERT_TRUE(std::regex_search(svg, fs, std::regex("data-arrow-label=\"0\"[^>]* font-size=\"([^\"]+)\"")));
    const double width = 0.6 * std::stod(fs[1]) * std::string("F 10.2 N").size();
    EXPECT_GE(k == 0 ? at : at - width, std::stod(vb[1]));
    EXPECT_LE(k == 0 ? at + width : at, std::stod(vb[1]) + std::stod(vb[3]));
    if (k == 0) {
      EXPECT_GT(at, tip);
      EXPECT_EQ(text[2], "start");
      EXPECT_EQ(text[3], "auto");  // pointing up: the label above its baseline
    } else {
      EXPECT_LT(at, tip);
      EXPECT_EQ(text[2], "end");
      EXPECT_EQ(text[3], "hanging");  // pointing down: the label below the head
    }
  }
}

}  // namespace
}  // namespace rdyn::validate
