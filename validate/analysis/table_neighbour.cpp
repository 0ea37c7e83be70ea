// What a sweep's previous table tells the next case (validate/analysis/calibrate.hpp,
// TableNeighbour): the mechanism's topology and how near rank loss its grid came.
#include <fmt/format.h>

#include "validate/analysis/calibrate.hpp"

namespace rdyn::validate {

std::string topology_key(const models::Scene& scene) {
  std::string key = fmt::format("{}:{}|", scene.independent.size(), scene.independent);
  auto str = [&](const std::string& s) { key += fmt::format("{}:{},", s.size(), s); };
  for (const auto& j : scene.joints) str(j.name), str(j.parent), str(j.child), key += std::to_string(static_cast<int>(j.type));
  key += "|";
  for (const auto& l : scene.loops) str(l.name), str(l.body_a), str(l.body_b);
  key += "|";
  for (const auto& g : scene.gears) str(g.driver), str(g.driven);
  return key;
}

std::optional<TableNeighbour> neighbour_of(const models::Scene& scene, const CalibrationTable& table) {
  if (!table.samples.periodic) return std::nullopt;
  return TableNeighbour{topology_key(scene), table.samples.min_conditioning};
}

}  // namespace rdyn::validate
