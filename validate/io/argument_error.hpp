// The error for a command-line value out of its documented range (README, "Limits"); main maps it
// to exit status 2. Its own header because the harness throws it too (validate/harness/peers.cpp,
// check_peers), and the harness must not include the subcommands (validate/cli/commands.hpp).
#pragma once

#include <stdexcept>

namespace rdyn::validate {

// A command-line value out of its documented range (exit status 2).
class ArgumentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace rdyn::validate
