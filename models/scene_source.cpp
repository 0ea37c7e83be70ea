#include "models/scene_source.hpp"

#include <yaml-cpp/yaml.h>

#include <utility>

#include "models/yaml_fields.hpp"

namespace rdyn::models {

struct SceneSource::Parsed {
  std::string file;  // the resolved path, as messages and Scene::source_file name it
  std::string text;
  YAML::Node root;   // checked by load_checked_yaml; never given out, only copied
};

SceneSource::SceneSource(std::string name_or_path) : name_or_path_(std::move(name_or_path)) {
  try {
    auto p = std::make_unique<Parsed>();
    p->file = resolve_scene_path(name_or_path_);
    p->text = read_scene_text(name_or_path_);
    p->root = yaml::load_checked_yaml(p->text, p->file);
    parsed_ = std::move(p);
  } catch (const SceneError&) {
    // Every load fails as load_scene does (its message is the one a user must see).
  }
}

SceneSource::~SceneSource() = default;
SceneSource::SceneSource(SceneSource&&) noexcept = default;
SceneSource& SceneSource::operator=(SceneSource&&) noexcept = default;

Scene SceneSource::load(const std::vector<Override>& overrides) {
  if (!parsed_) return load_scene(name_or_path_, overrides);
  try {
    return yaml::read_scene_tree(yaml::clone_with_marks(parsed_->root), parsed_->file, overrides);
  } catch (...) {
    // The text again, as load_scene reads it: the message (file, line, field) is parse_scene's
    // by construction, whatever the copy would have said.
    return parse_scene(parsed_->text, parsed_->file, overrides);
  }
}

}  // namespace rdyn::models
