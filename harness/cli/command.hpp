#pragma once
// Sub-command plumbing for pvbench.  Each sub-command lives in its own
// cmd_<name>.cpp, adds itself to the CLI11 app and returns a runner that is
// called after parsing.  Runners throw pvb::Error on bad input; main() turns
// that into one error line and a non-zero exit.
#include <CLI/CLI.hpp>
#include <functional>

namespace pvb::cli {

struct Command {
  CLI::App* app = nullptr;       ///< the CLI11 sub-command
  std::function<int()> run;      ///< called when this sub-command was given
};

}  // namespace pvb::cli
