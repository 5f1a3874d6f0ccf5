// Every JSON file that pvbench wrote during the test run parses with a
// strict parser: JSON has no NaN or Infinity (a value that is not a number
// is null, with a reason beside it), no trailing commas or comments, and
// nothing after the value.  yaml-cpp, which pvbench reads JSON with, would
// accept all of those, so the files are read here with nlohmann::json.
//
//   test_json_outputs STAMP FOLDER...
//
// Only files written after STAMP (touched when the run started) are read;
// folders that do not exist are skipped.
//
// A file that a test writes broken on purpose, as bad input, must be named
// *.invalid.json; it is skipped.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::vector<std::string> g_folders;
fs::file_time_type g_run_started = fs::file_time_type::min();

bool written_broken_on_purpose(const fs::path& p) {
  const std::string s = p.string();
  return s.size() > 13 && s.compare(s.size() - 13, 13, ".invalid.json") == 0;
}

/// The parser's complaint about `path`, or "" when it is strict JSON.
std::string strict_parse_error(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json parsed =
        nlohmann::json::parse(text.str(), nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/false);
    if (parsed.is_discarded()) return "discarded";
  } catch (const nlohmann::json::parse_error& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(JsonOutputs, EveryJsonFileIsStrictJson) {
  std::size_t checked = 0;
  for (const std::string& folder : g_folders) {
    std::error_code ec;
    if (!fs::is_directory(folder, ec)) continue;
    for (auto it = fs::recursive_directory_iterator(folder, fs::directory_options::skip_permission_denied, ec);
         it != fs::recursive_directory_iterator(); it.increment(ec)) {
      if (ec) break;
      if (!it->is_regular_file(ec) || it->path().extension() != ".json") continue;
      if (it->last_write_time(ec) < g_run_started) continue;  // from an earlier run
      if (written_broken_on_purpose(it->path())) continue;
      ++checked;
      const std::string error = strict_parse_error(it->path());
      EXPECT_EQ(error, "") << it->path();
    }
  }
  std::printf("checked %zu JSON files\n", checked);
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  if (argc < 2) {
    std::fprintf(stderr, "usage: test_json_outputs STAMP FOLDER...\n");
    return 2;
  }
  std::error_code ec;
  g_run_started = fs::last_write_time(argv[1], ec);
  if (ec) g_run_started = fs::file_time_type::min();  // no stamp: every file
  for (int i = 2; i < argc; ++i) g_folders.push_back(argv[i]);
  return RUN_ALL_TESTS();
}
