// `rdyn expand SCENE`: the scene as rdyn reads it — generators applied, --set overrides in,
// every value explicit — written back as YAML (models/scene_write.hpp) that every command
// loads as the same scene.
#pragma once

#include <string>
#include <vector>

namespace rdyn::validate {

struct ExpandArgs {
  std::string scene;
  std::vector<std::string> sets;
  std::string out = "/dev/stdout";
  bool force = false;  // replace a file rdyn did not write
};

// Whether a file's first bytes are a scene `rdyn expand` wrote (so a re-run may replace it).
bool is_rdyn_expanded_scene(const std::string& head);

// Loads and checks the scene, writes it checked (it must read back as the same scene) through
// an OutputFile; returns 0. Throws SceneError (exit 2), OutputError (exit 2) or NumericalError
// (exit 1: the written scene would not read back equal).
int run_expand(const ExpandArgs& args);

}  // namespace rdyn::validate
