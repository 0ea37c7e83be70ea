#include "validate/cli/expand.hpp"

#include "models/scene_write.hpp"
#include "models/scene_yaml.hpp"
#include "validate/io/output_dir.hpp"

namespace rdyn::validate {

bool is_rdyn_expanded_scene(const std::string& head) {
  return head.rfind("# Written by rdyn from scene '", 0) == 0;  // scene_to_yaml's first line
}

int run_expand(const ExpandArgs& a) {
  std::vector<models::Override> overrides;
  for (const auto& s : a.sets) overrides.push_back(models::parse_override(s));
  const models::Scene scene = models::load_scene(a.scene, overrides);
  OutputFile out(a.out, a.force, is_rdyn_expanded_scene);  // fails early on an unusable destination
  out.write(models::scene_to_yaml_checked(scene));
  out.commit();
  return 0;
}

}  // namespace rdyn::validate
