// `rdyn sweep --vary key=a:b:n`: the text of one axis as typed on the command line, read with the
// command line's number rules (validate/cli/decimal_number.hpp). Beside the other command-line
// readers, so the sweep itself (validate/analysis/sweep.hpp) does not depend on the command line.
#pragma once

#include <string>

#include "validate/analysis/sweep.hpp"

namespace rdyn::validate {

// "key=a:b:n" → n values from a to b (n ≥ 1; n = 1 gives a). Throws models::SceneError.
SweepAxis parse_sweep_axis(const std::string& text);

}  // namespace rdyn::validate
