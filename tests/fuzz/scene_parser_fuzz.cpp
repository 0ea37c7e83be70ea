// libFuzzer target for the scene parser: any input must either parse into a checked scene or
// raise SceneError — never crash, hang, or trip a sanitizer. Build and run (README):
//   cmake -S . -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DRDYN_FUZZ=ON
//   cmake --build build-fuzz --target rdyn_fuzz_scene
//   ./build-fuzz/rdyn_fuzz_scene -max_total_time=600 -max_len=4096 build-fuzz/corpus tests/fuzz/corpus
#include <cstddef>
#include <cstdint>
#include <string>

#include "models/scene_yaml.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    rdyn::models::parse_scene(text, "fuzz.yaml");
  } catch (const rdyn::models::SceneError&) {
    // Refused with a message: the expected outcome for bad input.
  }
  return 0;
}
