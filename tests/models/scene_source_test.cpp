// SceneSource (models/scene_source.cpp): a scene parsed once and loaded with overrides gives what
// load_scene gives — the same scene, the same key lines and, on a refusal, the same message —
// checked against load_scene, the independent route, on every shipped scene and on refusals.
#include "models/scene_source.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "models/scene_write.hpp"
#include "tests/models/scene_yaml_checks.hpp"

namespace rdyn::models {
namespace {

// Everything a load gives: the scene as written, where its keys were given, its file.
void expect_same_scene(const Scene& a, const Scene& b, const std::string& what) {
  EXPECT_EQ(scene_to_yaml(a), scene_to_yaml(b)) << what;
  EXPECT_EQ(a.key_lines, b.key_lines) << what;
  EXPECT_EQ(a.key_overrides, b.key_overrides) << what;
  EXPECT_EQ(a.source_file, b.source_file) << what;
}

// The refusal of a load, or a test failure when it loads.
template <typename Load>
SceneError refusal_of(Load&& load) {
  try {
    load();
  } catch (const SceneError& e) {
    return e;
  }
  ADD_FAILURE() << "loaded";
  return SceneError("", 0, "", "");
}

void expect_same_refusal(const SceneError& a, const SceneError& b) {
  EXPECT_STREQ(a.what(), b.what());
  EXPECT_EQ(a.file(), b.file());
  EXPECT_EQ(a.line(), b.line());
  EXPECT_EQ(a.field(), b.field());
}

// A scene file written for the test, removed with it.
struct TempScene {
  std::string path;
  explicit TempScene(const std::string& text)
      : path((std::filesystem::temp_directory_path() / ("rdyn_scene_source_" + std::to_string(::getpid()) + ".yaml"))
                 .string()) {
    std::ofstream(path) << text;
  }
  ~TempScene() { std::filesystem::remove(path); }
};

TEST(SceneSource, EveryShippedSceneLoadsAsLoadScene) {
  int scenes = 0, with_lines = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(RDYN_SCENES)) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string path = entry.path().string();
    SceneSource source(path);
    ASSERT_TRUE(source.parsed()) << path;
    const Scene a = source.load(), b = load_scene(path);
    expect_same_scene(a, b, path);
    ++scenes;
    for (const auto& [key, line] : a.key_lines) with_lines += line > 0 ? 1 : 0;
  }
  EXPECT_GE(scenes, 20);
  EXPECT_GT(with_lines, 0);  // the copies kept the file's lines (a copy without marks gives 0)
}

TEST(SceneSource, OverriddenLoadsDoNotChangeTheSource) {
  SceneSource source("bicycle");
  ASSERT_TRUE(source.parsed());
  // Heights in turn, then the first again: each load starts from the file, not the last load.
  for (const char* h : {"1.6", "1.9", "1.75", "1.6"}) {
    const std::vector<Override> o{{"bicycle_leg.subject.height_m", h}, {"bicycle_leg.resistance.power_W", "140"}};
    expect_same_scene(source.load(o), load_scene("bicycle", o), h);
  }
  // A key the file does not give (created by the override) and a load without overrides after it.
  const std::vector<Override> created{{"bicycle_leg.flywheel.inertia_kgm2", "0.3"}};
  expect_same_scene(source.load(created), load_scene("bicycle", created), "created key");
  expect_same_scene(source.load(), load_scene("bicycle"), "no overrides");
}

TEST(SceneSource, RefusalsAreLoadScenesMessages) {
  SceneSource source("bicycle");
  // A value that is no number (names the override), one out of the generator's range, an
  // unknown key path, and a key the scene's reader does not know.
  for (const std::vector<Override>& o : std::vector<std::vector<Override>>{
           {{"bicycle_leg.subject.height_m", "tall"}},
           {{"bicycle_leg.subject.height_m", "9"}},
           {{"bodies.nothing.mass_kg", "1"}},
           {{"bicycle_leg.subject.weight_kg", "70"}}}) {
    const SceneError a = refusal_of([&] { source.load(o); });
    const SceneError b = refusal_of([&] { load_scene("bicycle", o); });
    expect_same_refusal(a, b);
  }
  // After refusals the source still loads as the file says.
  expect_same_scene(source.load(), load_scene("bicycle"), "after refusals");
}

TEST(SceneSource, AFileThatDoesNotParseFailsEveryLoadAsLoadScene) {
  SceneSource missing("no-such-scene-anywhere");
  EXPECT_FALSE(missing.parsed());
  expect_same_refusal(refusal_of([&] { missing.load(); }), refusal_of([&] { load_scene("no-such-scene-anywhere"); }));
  const TempScene broken("name: x\nbodies: [\n");
  SceneSource source(broken.path);
  EXPECT_FALSE(source.parsed());
  expect_same_refusal(refusal_of([&] { source.load(); }), refusal_of([&] { load_scene(broken.path); }));
}

// A line-numbered refusal after loading: the node's line must be the file's, from the copy's marks.
TEST(SceneSource, ARefusalInTheFileNamesItsLine) {
  const std::string text = test::kFourbar;  // the four-bar the reader's own tests use
  const TempScene file(text);
  SceneSource source(file.path);
  ASSERT_TRUE(source.parsed());
  expect_same_scene(source.load(), load_scene(file.path), "four-bar");
  // A negative mass is found by check_scene, which knows the field and looks up its line.
  const std::vector<Override> o{{"bodies.rocker.mass_kg", "-1"}};
  expect_same_refusal(refusal_of([&] { source.load(o); }), refusal_of([&] { load_scene(file.path, o); }));
  const SceneError e = refusal_of([&] { source.load({{"joints.rocker.type", "helical"}}); });
  EXPECT_EQ(e.line(), 0);  // an override's value: named by the override, no line
  EXPECT_NE(std::string(e.what()).find("--set joints.rocker.type"), std::string::npos) << e.what();
}

// Aliases share one node in yaml-cpp's tree: an override through one name changes the other too,
// in the copy as in the file's own tree.
TEST(SceneSource, AliasesStaySharedInTheCopies) {
  const std::string text =
      test::with(test::with(test::kFourbar, "mass_kg: 0.5", "mass_kg: &m 0.5"), "mass_kg: 0.9", "mass_kg: *m");
  const TempScene file(text);
  SceneSource source(file.path);
  const std::vector<Override> o{{"bodies.crank.mass_kg", "0.7"}};
  const Scene a = source.load(o);
  expect_same_scene(a, load_scene(file.path, o), "alias");
  EXPECT_EQ(a.find_body("rocker")->mass_kg, a.find_body("crank")->mass_kg);
  expect_same_scene(source.load(), load_scene(file.path), "alias, no override");
}

}  // namespace
}  // namespace rdyn::models
