// The neighbour record of a sweep's table (validate/analysis/table_neighbour.cpp): the topology
// key ignores every number and names every joint, loop and gear; only a periodic table leaves one.
#include <gtest/gtest.h>

#include "models/scene_yaml.hpp"
#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {
namespace {

TEST(TableNeighbour, TheTopologyKeyIgnoresNumbersAndNamesTheStructure) {
  const auto a = models::load_scene("bicycle", {{"bicycle_leg.subject.height_m", "1.6"}});
  const auto b = models::load_scene("bicycle", {{"bicycle_leg.subject.height_m", "1.9"}});
  EXPECT_EQ(topology_key(a), topology_key(b));  // the same mechanism, other sizes
  EXPECT_NE(topology_key(a), topology_key(models::load_scene("fourbar")));
  auto renamed = models::load_scene("fourbar");
  const std::string key = topology_key(renamed);
  renamed.joints[1].name += "_x";
  EXPECT_NE(topology_key(renamed), key);
  auto regeared = models::load_scene("fourbar");
  regeared.gears.push_back({"g", regeared.joints[0].name, regeared.joints[2].name, 2.0});
  EXPECT_NE(topology_key(regeared), key);
}

TEST(TableNeighbour, OnlyAPeriodicTableLeavesANeighbourWithItsConditioning) {
  const auto scene = models::load_scene("fourbar");
  CalibrationTable t;
  t.samples.periodic = true;
  t.samples.min_conditioning = 0.3;
  const auto n = neighbour_of(scene, t);
  ASSERT_TRUE(n.has_value());
  EXPECT_EQ(n->topology, topology_key(scene));
  EXPECT_EQ(n->min_conditioning, 0.3);
  t.samples.periodic = false;
  EXPECT_FALSE(neighbour_of(scene, t).has_value());
}

}  // namespace
}  // namespace rdyn::validate
