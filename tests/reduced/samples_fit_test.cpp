// check_samples_fit (reduced/samples_fit.cpp): a table fits the scene whose fingerprint it
// records; another scene's table is refused naming what the table tells of the difference — the
// scene its header names, its constraint lines against the scene's — not only two hashes.
#include "reduced/samples_fit.hpp"

#include <gtest/gtest.h>

#include <string>

#include "models/scene_hash.hpp"
#include "tests/reduced/analytic_source.hpp"

namespace rdyn::reduced {
namespace {

std::string refusal(const Samples& s, const models::Scene& scene) {
  try {
    check_samples_fit(s, scene);
  } catch (const TableError& e) {
    return e.what();
  }
  return "";
}

TEST(SamplesFit, TheOwnSceneFitsAnotherIsNamedWithItsConstraintLines) {
  auto scene = test::analytic_scene();
  scene.outputs.constraint_forces.clear();
  Samples s;
  s.file = "t.csv";
  s.scene = scene.name;
  s.names = {"m1", "m2"};
  s.scene_hash = models::scene_hash(scene);
  EXPECT_EQ(refusal(s, scene), "");
  // Same lines, another fingerprint: the mechanism (or load placement, branch) differs.
  s.scene_hash = *s.scene_hash + 1;
  std::string m = refusal(s, scene);
  EXPECT_NE(m.find("table t.csv was extracted from a different scene (its mechanism"), std::string::npos) << m;
  // The header names another scene: said first.
  s.scene = "fourbar";
  m = refusal(s, scene);
  EXPECT_NE(m.find("different scene ('fourbar') (its mechanism"), std::string::npos) << m;
  // The table has a constraint line the scene does not ask for: both lists are named.
  s.names = {"m1", "m2", "me1_rod", "me2_rod"};
  m = refusal(s, scene);
  EXPECT_NE(m.find("it has constraint lines for rod where scene '" + scene.name + "' asks for none"), std::string::npos)
      << m;
  // Without a recorded scene: re-extract.
  s.scene_hash.reset();
  EXPECT_NE(refusal(s, scene).find("does not record the scene"), std::string::npos);
}

}  // namespace
}  // namespace rdyn::reduced
