// A scene file read and parsed once, then loaded many times with different overrides (a sweep's
// cases): the YAML parse was ~12 % of the instructions of a sweep case that changes the mechanism
// (issue #28 item 3; yaml-cpp spends ~900 instructions a byte).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "models/scene.hpp"
#include "models/scene_yaml.hpp"

namespace rdyn::models {

// Loads give what load_scene(name_or_path, overrides) gives for the text read at construction:
// the same Scene (key_lines from the file's lines) and, when it fails, the same SceneError.
// Each load applies its overrides to a copy of the parsed tree that keeps the file's marks; a
// load that fails parses the text again through parse_scene, so every message is parse_scene's
// own. A file that cannot be read or parsed is not kept: every load is then load_scene's.
// One per thread: yaml-cpp updates a tree's bookkeeping even when reading it.
class SceneSource {
 public:
  explicit SceneSource(std::string name_or_path);
  ~SceneSource();
  SceneSource(SceneSource&&) noexcept;
  SceneSource& operator=(SceneSource&&) noexcept;

  Scene load(const std::vector<Override>& overrides = {});
  // Whether the text was read and parsed (loads then skip the parse).
  bool parsed() const { return parsed_ != nullptr; }

 private:
  struct Parsed;
  std::string name_or_path_;
  std::unique_ptr<Parsed> parsed_;
};

}  // namespace rdyn::models
