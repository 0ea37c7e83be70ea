// The animation record of summary.json: it reads back to the same scene (hash) and frames, bit for
// bit, after the JSON text round trip summary.json makes; the HTML drawn from it alone places
// every joint at the recorded pose, escapes every text a hand-edited summary could bring, and the
// optimize section holds both strategies.
#include "validate/report/cycle_animation.hpp"

#include <cmath>
#include <regex>

#include <gtest/gtest.h>

#include "models/pose.hpp"
#include "models/scene_hash.hpp"
#include "models/scene_yaml.hpp"
#include "validate/analysis/mechanism_run.hpp"

namespace rdyn::validate {
namespace {

// A record of the four-bar with its constraint force drawn: one cycle from t = 0.2 s.
nlohmann::json fourbar_record(const std::string& title) {
  auto s = models::load_scene("fourbar", {});
  const CycleStart c{0.2, s.initial.q, s.initial.qdot, 0.3};
  return animation_record(s, c, simulate_cycle(s, c, 12), title);
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(CycleAnimation, RecordReadsBackBitForBitThroughSummaryJson) {
  const auto s = models::load_scene("fourbar", {});
  const nlohmann::json rec = fourbar_record("t");
  const auto back = read_animation_record(nlohmann::json::parse(rec.dump(2)));
  EXPECT_EQ(models::scene_hash(back.scene), models::scene_hash(s));
  EXPECT_EQ(back.start.t_s, 0.2);
  EXPECT_EQ(back.start.duration_s, 0.3);
  ASSERT_EQ(back.frames.t_s.size(), 13u);
  EXPECT_EQ(back.frames.t_s.front(), 0.2);
  EXPECT_NEAR(back.frames.t_s.back(), 0.5, 1e-15);
  const auto again = read_animation_record(rec);
  EXPECT_EQ(back.frames.q_joint, again.frames.q_joint);
  EXPECT_EQ(back.frames.q, again.frames.q);
  ASSERT_EQ(back.frames.arrows.size(), s.outputs.constraint_forces.size() + s.outputs.reactions.size());
  for (size_t a = 0; a < back.frames.arrows.size(); ++a) EXPECT_EQ(back.frames.arrows[a].fx_N, again.frames.arrows[a].fx_N);
  EXPECT_EQ(back.frames.traces, again.frames.traces);
}

TEST(CycleAnimation, HtmlPlacesEveryJointAtTheRecordedPose) {
  const nlohmann::json rec = fourbar_record("four-bar");
  const auto a = read_animation_record(rec);
  const std::string html = animation_record_html(rec);
  const auto pose = models::calc_pose(a.scene, a.frames.q_joint[0]);
  for (size_t j = 0; j < a.scene.joints.size(); ++j) {
    std::smatch m;
    const std::regex el("<circle data-joint=\"" + a.scene.joints[j].name +
                        "\" data-i=\"[0-9]+\" data-x=\"([^\"]+)\" data-y=\"([^\"]+)\"");
    ASSERT_TRUE(std::regex_search(html, m, el)) << a.scene.joints[j].name;
    EXPECT_EQ(std::stod(m[1]), pose.joints[j].x);
    EXPECT_EQ(std::stod(m[2]), pose.joints[j].y);
  }
  EXPECT_EQ(count(html, "<div class=\"animation\""), 1);
  EXPECT_NE(html.find("<h3>four-bar</h3>"), std::string::npos);
}

TEST(CycleAnimation, HandEditedTextIsEscapedAndBadRecordsAreRefused) {
  nlohmann::json rec = fourbar_record("a </script><b>title");
  ASSERT_FALSE(rec["frames"]["arrows"].empty());
  rec["frames"]["arrows"][0]["name"] = "</script><script>alert(1)</script>";
  const std::string html = animation_record_html(rec);
  EXPECT_NE(html.find("a &lt;/script&gt;&lt;b&gt;title"), std::string::npos);
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_EQ(count(html, "</script>"), 2);  // the frames' JSON and the page's script, each closed once
  nlohmann::json summary;
  summary["animation_error"] = "no <cycle>";
  EXPECT_NE(validate_animation_html(summary).find("Not animated: no &lt;cycle&gt;"), std::string::npos);
  EXPECT_EQ(validate_animation_html(nlohmann::json::object()), "");
  nlohmann::json wrong = fourbar_record("t");
  wrong["frames"]["q_joint"][3].erase(0);
  EXPECT_THROW(read_animation_record(wrong), std::invalid_argument);
  nlohmann::json missing = fourbar_record("t");
  missing.erase("frames");
  try {  // a hand-edited summary: the message names the JSON path of what is missing or mistyped
    read_animation_record(missing, "animations.constant");
    ADD_FAILURE() << "a record without frames was read";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "summary.json: animations.constant.frames is missing");
  }
  nlohmann::json mistyped = fourbar_record("t");
  mistyped["frames"]["arrows"] = {{{"name", "a"}, {"body", "crank"}, {"point", {0, "x"}}}};
  try {
    read_animation_record(mistyped);
    ADD_FAILURE() << "an arrow's point [0, \"x\"] was read";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "summary.json: animation.frames.arrows[0].point is not of the type rdyn writes there");
  }
  nlohmann::json bad_scene = fourbar_record("t");
  bad_scene["scene_yaml"] = "bodies: [";
  EXPECT_THROW(read_animation_record(bad_scene), models::SceneError);
}

TEST(CycleAnimation, OptimizeSectionHoldsBothStrategies) {
  nlohmann::json summary;
  EXPECT_EQ(strategies_animation_html(summary), "");
  summary["animations"]["constant"] = fourbar_record("constant");
  summary["animations"]["optimised"] = fourbar_record("optimised");
  const std::string html = strategies_animation_html(summary);
  EXPECT_EQ(count(html, "<div class=\"animation\""), 2);
  const auto c = html.find("data-strategy=\"constant\""), o = html.find("data-strategy=\"optimised\"");
  ASSERT_NE(c, std::string::npos);
  ASSERT_NE(o, std::string::npos);
  EXPECT_LT(c, html.find("<h3>constant</h3>"));
  EXPECT_LT(html.find("<h3>constant</h3>"), o);
  EXPECT_LT(o, html.find("<h3>optimised</h3>"));
}

// The validate report's words follow the record: a whole revolution is "one steady cycle"; the
// last stretch of a coordinate that does not turn says neither "cycle" nor "revolution".
TEST(CycleAnimation, ValidateSectionSaysCycleOnlyForARevolution) {
  nlohmann::json summary;
  summary["animation"] = fourbar_record("t");
  EXPECT_NE(validate_animation_html(summary).find("<h2>The mechanism over one steady cycle</h2>"), std::string::npos);
  summary["animation"]["start"]["revolution"] = false;
  const std::string html = validate_animation_html(summary);
  EXPECT_NE(html.find("<h2>The mechanism over the end of the run</h2>"), std::string::npos);
  EXPECT_EQ(html.find("cycle"), std::string::npos);
  EXPECT_EQ(html.find("revolution"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::validate
