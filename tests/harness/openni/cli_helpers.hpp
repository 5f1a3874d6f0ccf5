#pragma once
// What the pvbench camera tests share: running pvbench from the source
// folder with its output captured, and reading its outputs.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"

namespace pvb::test {

struct CliResult {
  int code = -1;
  std::string output;
};

/// Runs `env pvbench args` from the source folder (so that sim://scenes/...
/// resolves as in the README), stdout and stderr together.
inline CliResult run_pvbench(const std::string& env, const std::string& args) {
  const std::string log = ::testing::TempDir() + "pvb_cli_" + std::to_string(::getpid()) + ".txt";
  const std::string cmd = "cd " + std::string(PVB_SOURCE_DIR) + " && " + env + " " + std::string(PVB_BINARY_DIR) +
                          "/bin/pvbench " + args + " > " + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, pvb::read_file(log)};
}

/// The lines of a text file that are neither empty nor comments.
inline std::vector<std::string> data_lines(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  for (std::string l; std::getline(in, l);)
    if (!l.empty() && l[0] != '#') out.push_back(l);
  return out;
}

/// A number in a JSON text by key; -1 when absent.
inline double json_number(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": ([-0-9.eE+]+)");
  std::smatch m;
  if (!std::regex_search(json, m, re)) return -1;
  return std::stod(m[1]);
}

/// Lines of output that say "error".
inline std::vector<std::string> error_lines(const std::string& output) {
  std::vector<std::string> out;
  std::istringstream in(output);
  for (std::string l; std::getline(in, l);)
    if (l.find("error") != std::string::npos) out.push_back(l);
  return out;
}

inline void expect_one_error_line(const CliResult& r, const std::string& must_contain) {
  EXPECT_NE(r.code, 0) << r.output;
  const std::vector<std::string> errors = error_lines(r.output);
  ASSERT_EQ(errors.size(), 1u) << r.output;
  EXPECT_NE(errors[0].find(must_contain), std::string::npos) << errors[0];
}

}  // namespace pvb::test
