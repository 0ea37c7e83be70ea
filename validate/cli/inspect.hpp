// `rdyn inspect SCENE`: the assembled configuration, degrees of freedom, loop closure gaps and
// the range of the independent coordinate, as JSON on standard output (engine/inspect.hpp
// computes them).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/inspect.hpp"

namespace rdyn::validate {

// The JSON `rdyn inspect` prints (README, "rdyn inspect"): angles in degrees and lengths in
// metres, as the scene writes them.
nlohmann::json inspection_json(const models::Scene& scene, const engine::Inspection& inspection);

// The assembled configuration as run.json records it: {"<joint>": {"q_deg"|"q_m": value}}.
nlohmann::json assembly_json(const engine::Inspection& assembly);

struct InspectArgs {
  std::string scene;
  std::vector<std::string> sets;
  std::string svg;     // --svg FILE: also draw the assembled configuration (empty: no drawing)
  bool force = false;  // replace an existing FILE rdyn did not write
};
// Prints the JSON on standard output and the warnings on standard error; returns 0. Throws like
// the other commands (SceneError, EngineError: exit 2; NumericalError: exit 1).
int run_inspect(const InspectArgs& args);

}  // namespace rdyn::validate
