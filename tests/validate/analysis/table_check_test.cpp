// check_table_against_scene: a table without its content checksum is compared with a fresh
// extraction; an unedited one passes, an edited value or a deleted `# pole` line is refused with
// the table's line.
#include "validate/analysis/table_check.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <string>

#include "models/scene_yaml.hpp"
#include "validate/analysis/build_reduced.hpp"

namespace rdyn::validate {
namespace {

// The table as `rdyn extract` writes it, its checksum removed, read back.
std::string unchecked_text(const models::Scene& scene, double grid_deg) {
  std::string text = reduced::format_samples_csv(extract_from_full(scene, grid_deg, reduced::Method::Kinetostatic).samples);
  text.erase(text.find(" content="), 9 + 16);
  return text;
}

std::string message_of(const reduced::Samples& t, const models::Scene& scene) {
  try {
    check_table_against_scene(t, scene);
  } catch (const reduced::TableError& e) {
    return e.what();
  }
  return "";
}

TEST(TableCheck, UneditedPassesAnEditedValueIsRefusedWithItsLine) {
  const auto scene = models::load_scene("fourbar");
  const std::string text = unchecked_text(scene, 10);
  const auto t = reduced::parse_samples_csv(text, "t.csv");
  ASSERT_FALSE(t.content_checked);
  EXPECT_EQ(message_of(t, scene), "");
  // m2 on the sixth row changed in its 4th significant digit: the file's line is named.
  auto edited = t;
  const int c = edited.column("m2");
  ASSERT_GE(c, 0);
  double scale = 0;
  for (double v : edited.columns[c]) scale = std::max(scale, std::abs(v));
  edited.columns[c][5] += 1e-4 * scale;
  const std::string m = message_of(edited, scene);
  EXPECT_NE(m.find(fmt::format("t.csv:{}: column 'm2' at q = {:g}°", t.header_line + 6, t.q[5] * 180 / M_PI)),
            std::string::npos)
      << m;
  // Below the check's tolerance (a table from a version whose calls round differently) passes.
  edited.columns[c][5] = t.columns[c][5] + 0.1 * kTableCheckRelTol * scale;
  EXPECT_EQ(message_of(edited, scene), "");
}

// The isosceles slider-crank's rod force has a pole where it folds: without the `# pole` line
// the reduced model would interpolate straight through it (0.23 N for 28.4 N).
TEST(TableCheck, ADeletedPoleLineIsRefused) {
  const auto scene = models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/iso-slider-crank.yaml");
  std::string text = unchecked_text(scene, 10);
  const size_t pole = text.find("# pole ");
  ASSERT_NE(pole, std::string::npos) << text.substr(0, 400);
  EXPECT_EQ(message_of(reduced::parse_samples_csv(text, "t.csv"), scene), "");
  text.erase(pole, text.find('\n', pole) + 1 - pole);
  const std::string m = message_of(reduced::parse_samples_csv(text, "t.csv"), scene);
  EXPECT_NE(m.find("t.csv:3: "), std::string::npos) << m;  // where the line was (after '# singular')
  EXPECT_NE(m.find("'# pole rod_axial' line is missing"), std::string::npos) << m;
  // Without its '# singular' line either: that is named first, at line 2 where it belongs (the
  // message said it "lists 0 configuration(s)", of a line that was not there).
  const size_t singular = text.find("# singular:");
  ASSERT_NE(singular, std::string::npos);
  text.erase(singular, text.find('\n', singular) + 1 - singular);
  const std::string m2 = message_of(reduced::parse_samples_csv(text, "t.csv"), scene);
  EXPECT_NE(m2.find("t.csv:2: "), std::string::npos) << m2;
  EXPECT_NE(m2.find("it has no '# singular' line where the scene has 1 singular configuration(s)"), std::string::npos)
      << m2;
}

// A header edited from periodic=1 to 0 is named as such (it was reported as a grid of 36 points
// against the scene's 35).
TEST(TableCheck, AnEditedPeriodicFlagIsNamed) {
  const auto scene = models::load_scene("fourbar");
  auto t = reduced::parse_samples_csv(unchecked_text(scene, 30), "t.csv");
  ASSERT_TRUE(t.periodic);
  t.periodic = false;
  const std::string m = message_of(t, scene);
  EXPECT_NE(m.find("t.csv:1: "), std::string::npos) << m;
  EXPECT_NE(m.find("its header says periodic=0 where the scene's table is periodic"), std::string::npos) << m;
}

// A `# singular` line with as many configurations as the scene's, one moved by 1 mm: the message
// names both positions (it used to say "lists 1 where the scene has 1").
TEST(TableCheck, AMovedSingularConfigurationIsNamed) {
  const auto scene = models::load_scene(std::string(RDYN_SOURCE_DIR) + "/tests/validate/scenes/iso-slider-crank.yaml");
  auto t = reduced::parse_samples_csv(unchecked_text(scene, 10), "t.csv");
  ASSERT_EQ(t.singular_q.size(), 1u);
  const double was = t.singular_q[0];
  t.singular_q[0] += 1e-3;
  const std::string m = message_of(t, scene);
  EXPECT_NE(m.find(fmt::format("lists q = {:g} m where the scene's singular configuration is at q = {:g} m",
                               was + 1e-3, was)),
            std::string::npos)
      << m;
}

}  // namespace
}  // namespace rdyn::validate
