// Shared by the engine tests that check refusals of a scene (full_model_test, mobility_test).
#pragma once

#include <string>

#include "engine/full_model.hpp"

namespace rdyn::test {

// The message of the EngineError that building a workspace of `scene` throws ("" if none).
inline std::string refusal(const models::Scene& scene) {
  using namespace rdyn::engine;
  try {
    FullModel model(scene);
    FullWorkspace ws(model);
  } catch (const EngineError& e) {
    return e.what();
  }
  return "";
}

inline bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace rdyn::test
