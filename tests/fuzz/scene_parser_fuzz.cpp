// libFuzzer target for the scene parser: any input must either parse into a checked scene or
// raise SceneError — never crash, hang, or trip a sanitizer. Two modes, chosen by the input:
//   YAML      (default) the input is a scene file;
//   overrides an input starting with "--set\n": the next line picks a shipped scene (by name,
//             or by its length when no name matches), every further line is one `--set`
//             override (parse_override, then parse_scene of that scene with them).
// Build and run (README). RDYN_SANITIZE adds ASan/UBSan to the library too; the coverage
// flag makes libFuzzer see inside the parser, not only this file:
//   cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DRDYN_FUZZ=ON -DRDYN_SANITIZE=ON \
//         -DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link
//   cmake --build build-fuzz --target rdyn_fuzz_scene
//   ./build-fuzz/rdyn_fuzz_scene -max_total_time=600 -max_len=4096 build-fuzz/corpus
//   tests/fuzz/corpus
#include <cstddef>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "models/scene_yaml.hpp"

namespace {

// The shipped scenes' texts, read once (the fuzzer runs millions of inputs).
const std::map<std::string, std::string>& shipped_scenes() {
  static const std::map<std::string, std::string> texts = [] {
    std::map<std::string, std::string> t;
    for (const char* name : {"bicycle", "fourbar", "slider-crank"})
      t[name] = rdyn::models::read_scene_text(std::string(RDYN_SCENES_DIR) + "/" + name + ".yaml");
    for (const char* name : {"coarse-grid", "high-cadence", "high-saddle", "light-flywheel",
                             "motor-startup", "parallelogram", "stall", "thousand-cycles"})
      t[name] =
          rdyn::models::read_scene_text(std::string(RDYN_SCENES_DIR) + "/hard/" + name + ".yaml");
    return t;
  }();
  return texts;
}

void fuzz_overrides(const std::string& text) {
  std::istringstream in(text);
  std::string scene_name;
  std::getline(in, scene_name);
  const auto& scenes = shipped_scenes();
  auto it = scenes.find(scene_name);
  if (it == scenes.end()) {
    it = scenes.begin();
    std::advance(it, scene_name.size() % scenes.size());
  }
  std::vector<rdyn::models::Override> overrides;
  for (std::string line; std::getline(in, line) && overrides.size() < 16;)
    overrides.push_back(rdyn::models::parse_override(line));  // may throw SceneError
  rdyn::models::parse_scene(it->second, it->first + ".yaml", overrides);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  static const std::string kSetMode = "--set\n";
  try {
    if (text.compare(0, kSetMode.size(), kSetMode) == 0)
      fuzz_overrides(text.substr(kSetMode.size()));
    else
      rdyn::models::parse_scene(text, "fuzz.yaml");
  } catch (const rdyn::models::SceneError&) {
    // Refused with a message: the expected outcome for bad input.
  }
  return 0;
}
