#pragma once
// The data in ../shared (PVB_SHARED_DIR) that some tests read: a missing
// file or folder fails the test at once, naming the path, instead of
// reaching the code under test as an empty image or an empty list.
#include <sys/stat.h>

#include <stdexcept>
#include <string>

namespace pvb::test {

/// PVB_SHARED_DIR/relative; throws (a failure GoogleTest reports with the
/// message) when nothing is there.
inline std::string shared_path(const std::string& relative) {
  const std::string path = std::string(PVB_SHARED_DIR) + "/" + relative;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw std::runtime_error("missing shared test data: " + path +
                             " (the tests read ../shared/data beside the repository)");
  return path;
}

}  // namespace pvb::test
