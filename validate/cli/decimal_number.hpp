// Numbers typed on the command line, read as scene numbers are (models/scene_yaml.cpp): decimal
// only, and a literal a double cannot hold is refused as typed. CLI11 and sscanf alone read
// `0x10` as 16 (also 0b…, 0o…, hex floats) and `1e-400` as 0, which a scene refuses (issue #23).
#pragma once

#include <string>

namespace rdyn::validate {

// Empty when `text` is a plain decimal number ([+-]digits[.digits][e[+-]digits]; `whole`: digits
// only) that a double holds, or nan/inf (left to the option's range check, which names it);
// else why not, in plain words quoting the text as typed.
std::string check_decimal_number(const std::string& text, bool whole = false);

// The value of such a text; throws std::invalid_argument with check_decimal_number's reason.
double read_decimal_number(const std::string& text);

}  // namespace rdyn::validate
