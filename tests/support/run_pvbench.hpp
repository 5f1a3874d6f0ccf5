#pragma once
// Runs the built pvbench program from a test and captures what it printed.
// Output goes to a file named after the process id: ctest runs test
// processes in parallel.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "pvb/common/text.hpp"

namespace pvb::test {

inline const std::string& pvbench_path() {
  static const std::string path = std::string(PVB_BINARY_DIR) + "/bin/pvbench";
  return path;
}

struct RunResult {
  int code = -1;       ///< exit status (-1 if killed by a signal)
  std::string output;  ///< stdout and stderr together
};

/// Runs `pvbench ARGS` through the shell (ARGS is not quoted).
inline RunResult run_pvbench(const std::string& args) {
  const std::string log = ::testing::TempDir() + "pvb_run_" + std::to_string(::getpid()) + ".txt";
  const int status = std::system((pvbench_path() + " " + args + " > " + log + " 2>&1").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

}  // namespace pvb::test
