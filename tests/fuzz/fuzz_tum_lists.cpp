// Fuzz target: the TUM RGB-D folder's lists (rgb.txt, depth.txt,
// associations.txt) as TumSequenceReader reads them.  The input is split
// at the first two form feeds (\f) into the three files; with fewer, the
// missing files are absent, so the reader also associates rgb.txt with
// depth.txt itself.  Any input must give a reader or a pvb::Error.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "pvb/common/error.hpp"
#include "pvb/dataset/tum_sequence.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  const std::string dir = pvb::fuzz::scratch_dir() + "/sequence";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  std::size_t a = 0;
  for (int i = 0; i < 2; ++i) {
    const std::size_t b = text.find('\f', a);
    if (b == std::string::npos) break;
    parts.push_back(text.substr(a, b - a));
    a = b + 1;
  }
  parts.push_back(text.substr(a));
  const char* names[] = {"rgb.txt", "depth.txt", "associations.txt"};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string rel = std::string("sequence/") + names[i];
    pvb::fuzz::write_input(rel, reinterpret_cast<const std::uint8_t*>(parts[i].data()), parts[i].size());
  }
  try {
    pvb::dataset::TumSequenceReader reader(dir);
    (void)reader.size_hint();
    (void)pvb::dataset::read_tum_list(dir + "/rgb.txt");
  } catch (const pvb::Error&) {
  }
  return 0;
}
