#pragma once
// Reading what a pvbench run printed and wrote: trajectory lines, numbers
// in its JSON files, and its error lines.
#include <gtest/gtest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "run_pvbench.hpp"

namespace pvb::test {

/// The lines of a text file that are neither empty nor comments.
inline std::vector<std::string> data_lines(const std::string& path) {
  std::vector<std::string> out;
  std::ifstream in(path);
  for (std::string l; std::getline(in, l);)
    if (!l.empty() && l[0] != '#') out.push_back(l);
  return out;
}

/// The first number after "key": in a JSON text; -1 when absent.
inline double json_number(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\": *([-0-9.eE+]+)"))) return -1;
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

/// A failed run that printed exactly one error line, containing `must_contain`.
inline void expect_one_error_line(const RunResult& r, const std::string& must_contain) {
  EXPECT_NE(r.code, 0) << r.output;
  const std::vector<std::string> errors = error_lines(r.output);
  ASSERT_EQ(errors.size(), 1u) << r.output;
  EXPECT_NE(errors[0].find(must_contain), std::string::npos) << errors[0];
}

}  // namespace pvb::test
