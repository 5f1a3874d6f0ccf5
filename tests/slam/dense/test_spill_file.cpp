// SpillFile: records come back as written, released space is reused, and
// nothing is left in the folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/slam/dense/spill_file.hpp"

namespace {

using pvb::slam::dense::SpillFile;

std::string bytes(unsigned seed, std::size_t n) {
  std::mt19937 rng(seed);
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(rng() % 7);  // compressible, as map records are
  return s;
}

TEST(SpillFile, GivesRecordsBackAndLeavesNoFileInItsFolder) {
  const std::string dir = ::testing::TempDir() + "/spill_file_test";
  std::filesystem::create_directories(dir);
  SpillFile f(dir);
  EXPECT_EQ(f.file_bytes(), 0u);
  const std::string a = bytes(1, 10000), b = bytes(2, 3000), empty;
  const SpillFile::Extent ea = f.write(a), eb = f.write(b), ee = f.write(empty);
  EXPECT_LT(ea.stored_bytes, a.size());  // compressed
  EXPECT_EQ(f.read(ea), a);
  EXPECT_EQ(f.read(eb), b);
  EXPECT_EQ(f.read(ee), empty);
  EXPECT_EQ(f.live_raw_bytes(), a.size() + b.size());
  EXPECT_TRUE(std::filesystem::is_empty(dir));  // unlinked as soon as made
  f.release(ea);
  const std::uint64_t span = f.file_bytes();
  const SpillFile::Extent ec = f.write(bytes(3, 5000));  // fits in a's hole
  EXPECT_EQ(ec.offset, ea.offset);
  EXPECT_EQ(f.file_bytes(), span);
  EXPECT_EQ(f.read(eb), b);
  EXPECT_EQ(f.read(ec), bytes(3, 5000));
  EXPECT_EQ(f.writes(), 4u);
}

TEST(SpillFile, ANamedFolderThatDoesNotExistIsAnIoError) {
  SpillFile f("/nonexistent-folder/for/spill");
  EXPECT_THROW(f.write("x"), pvb::IoError);
}

}  // namespace
