// `rdyn animate SCENE`: one self-contained DIR/animation.html playing a simulated run of the
// mechanism (validate/report/mechanism_drawing.hpp), and `rdyn inspect SCENE --svg FILE`'s drawing.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/inspect.hpp"

namespace rdyn::validate {

struct AnimateArgs {
  std::string scene;
  std::string model = "full";        // full | reduced
  std::optional<double> duration;    // [s]; empty: the scene's
  std::optional<double> dt_out;      // [s]; empty: the scene's
  std::vector<std::string> traces;   // body.point; empty: the loops' closure points
  std::vector<std::string> sets;
  std::string out;
  bool force = false;
};
int run_animate(const AnimateArgs& args);

// `rdyn inspect --svg`: the assembled configuration drawn, with the independent coordinate's range
// and dead points noted; is_rdyn_svg recognises such a file (the first bytes), so a re-run may
// replace it.
std::string inspect_svg(const models::Scene& scene, const engine::Inspection& inspection);
bool is_rdyn_svg(const std::string& first_bytes);

}  // namespace rdyn::validate
