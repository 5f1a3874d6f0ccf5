// Vocabulary files: text and binary round trips, and bad files, each error
// naming the file and the line (text) or byte (binary).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "synthetic.hpp"

namespace {

using namespace pvb::slam::place;
using namespace pvb::slam::place::test;

/// A file under the test's temporary folder, removed at the end of scope.
struct TempFile {
  explicit TempFile(const std::string& name) : path(temp_path(name)) {}
  ~TempFile() {
    std::remove(path.c_str());
    std::remove((path + ".tmp").c_str());
  }
  std::string path;
};

std::string read_bytes(const std::string& path) { return pvb::read_file(path); }

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

/// A vocabulary trained on random descriptors (k = 4, L = 3), and the images.
struct Trained {
  Vocabulary voc;
  std::vector<cv::Mat> images;
};
Trained trained() {
  std::mt19937_64 rng(17);
  Trained t;
  for (int i = 0; i < 30; ++i) {
    std::vector<Desc> img;
    for (int j = 0; j < 60; ++j) img.push_back(random_desc(rng));
    t.images.push_back(to_mat(img));
  }
  TrainParams p;
  p.k = 4;
  p.levels = 3;
  t.voc = Vocabulary::train(t.images, p);
  return t;
}

void expect_same_tree(const Vocabulary& a, const Vocabulary& b) {
  ASSERT_EQ(a.k(), b.k());
  ASSERT_EQ(a.levels(), b.levels());
  ASSERT_EQ(a.node_count(), b.node_count());
  ASSERT_EQ(a.size(), b.size());
  for (NodeId n = 0; n < a.node_count(); ++n) {
    EXPECT_EQ(a.children(n), b.children(n)) << "node " << n;
    if (n > 0) {
      EXPECT_EQ(from_ptr(a.centre(n)), from_ptr(b.centre(n))) << "node " << n;
    }
  }
  for (WordId w = 0; w < a.size(); ++w) {
    EXPECT_EQ(a.word_node(w), b.word_node(w)) << "word " << w;
    EXPECT_EQ(a.word_weight(w), b.word_weight(w)) << "word " << w;  // exact
  }
}

TEST(VocabularyFiles, TextToBinaryToTextIsTheSameText) {
  TempFile text("rt.txt"), bin("rt.bin"), text2("rt2.txt");
  pvb::write_file(text.path, toy_text());
  Vocabulary::load(text.path).save_binary(bin.path);
  const Vocabulary from_bin = Vocabulary::load(bin.path);
  EXPECT_EQ(read_bytes(bin.path).compare(0, 8, "PVBVOC1\n"), 0);
  from_bin.save_text(text2.path);
  EXPECT_EQ(read_bytes(text2.path), toy_text());
}

TEST(VocabularyFiles, TextFieldsMaySeparateWithAnySpacesAndLinesEndWithCrLf) {
  TempFile canonical("ws_a.txt"), loose("ws_b.txt");
  pvb::write_file(canonical.path, toy_text());
  std::string text = toy_text();
  std::string out;
  for (const char c : text) {
    if (c == '\n')
      out += " \t\r\n";
    else if (c == ' ')
      out += "\t ";
    else
      out += c;
  }
  pvb::write_file(loose.path, out.substr(0, out.size() - 4));  // no newline at the end
  expect_same_tree(Vocabulary::load(canonical.path), Vocabulary::load(loose.path));
}

TEST(VocabularyFiles, TrainedVocabularyRoundTripsThroughBothFormats) {
  const Trained t = trained();
  TempFile bin("train.bin"), text("train.txt");
  t.voc.save_binary(bin.path);
  t.voc.save_text(text.path);
  const Vocabulary from_bin = Vocabulary::load(bin.path);
  const Vocabulary from_text = Vocabulary::load(text.path);
  expect_same_tree(t.voc, from_bin);
  expect_same_tree(t.voc, from_text);
  for (const cv::Mat& img : t.images) {
    BowVector a, b, c;
    FeatureVector fa, fb;
    t.voc.transform(img, &a, &fa, 2);
    from_bin.transform(img, &b, &fb, 2);
    from_text.transform(img, &c);
    EXPECT_EQ(a, b);
    EXPECT_EQ(a, c);
    EXPECT_EQ(fa, fb);
  }
  // The binary file is 24 + 45 bytes per node after the root + 8.
  EXPECT_EQ(read_bytes(bin.path).size(), 24 + 45 * (t.voc.node_count() - 1) + 8);
}

// The systems of one process share a vocabulary file's tree until the file
// is saved again.
TEST(VocabularyFiles, ASharedLoadIsReadOnceUntilTheFileChanges) {
  const Trained t = trained();
  TempFile bin("shared.bin");
  t.voc.save_binary(bin.path);
  const std::shared_ptr<const Vocabulary> first = Vocabulary::load_shared(bin.path);
  expect_same_tree(t.voc, *first);
  EXPECT_EQ(Vocabulary::load_shared(bin.path), first);
  TrainParams p;
  p.k = 3;
  p.levels = 2;
  const Vocabulary other = Vocabulary::train(t.images, p);
  other.save_binary(bin.path);
  const std::shared_ptr<const Vocabulary> again = Vocabulary::load_shared(bin.path);
  EXPECT_NE(again, first);
  expect_same_tree(other, *again);
  expect_same_tree(t.voc, *first);  // the first holders keep theirs
  std::remove(bin.path.c_str());
  EXPECT_THROW(Vocabulary::load_shared(bin.path), pvb::IoError);
}

TEST(VocabularyFiles, EmptyVocabularyIsNotSaved) {
  TempFile f("empty_save.bin");
  EXPECT_THROW(Vocabulary().save_binary(f.path), pvb::IoError);
  EXPECT_THROW(Vocabulary().save_text(f.path), pvb::IoError);
}

/// Loads `bytes` from a file and expects an IoError naming the file, with
/// `line` (0 for binary files) and a message containing `part`.
void expect_load_error(const std::string& name, const std::string& bytes, int line, const std::string& part) {
  TempFile f(name);
  write_bytes(f.path, bytes);
  try {
    Vocabulary::load(f.path);
    ADD_FAILURE() << name << ": loaded";
  } catch (const pvb::IoError& e) {
    EXPECT_EQ(e.file(), f.path) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_NE(e.message().find(part), std::string::npos) << name << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find(f.path), std::string::npos) << e.what();
  }
}

/// toy_text() with line `line` (1-based) replaced.
std::string toy_with_line(int line, const std::string& replacement) {
  std::istringstream in(toy_text());
  std::string l, out;
  for (int i = 1; std::getline(in, l); ++i) out += (i == line ? replacement : l) + "\n";
  return out;
}

TEST(VocabularyFiles, MissingFileNamesIt) {
  const std::string path = temp_path("does_not_exist.txt");
  try {
    Vocabulary::load(path);
    FAIL() << "loaded";
  } catch (const pvb::IoError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(e.message().find("cannot open"), std::string::npos) << e.what();
  }
}

// A vocabulary path that is not a regular file is refused before it is
// opened: a FIFO used to block the load for ever.
TEST(VocabularyFiles, OnlyRegularFilesAreOpened) {
  const std::string fifo = temp_path("voc_fifo");
  std::remove(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  try {
    Vocabulary::load(fifo);
    ADD_FAILURE() << "loaded";
  } catch (const pvb::IoError& e) {
    EXPECT_EQ(std::string(e.what()), fifo + ": is a FIFO; expected a regular file");
  }
  std::remove(fifo.c_str());
  const std::string dir = temp_path("voc_dir");
  ::mkdir(dir.c_str(), 0700);
  try {
    Vocabulary::load(dir);
    ADD_FAILURE() << "loaded";
  } catch (const pvb::IoError& e) {
    EXPECT_EQ(std::string(e.what()), dir + ": is a folder; expected a regular file");
  }
  ::rmdir(dir.c_str());
}

TEST(VocabularyFiles, BadTextFilesNameTheLine) {
  expect_load_error("empty.txt", "", 1, "empty file");
  expect_load_error("header3.txt", toy_with_line(1, "2 2 0"), 1, "k L scoring weighting");
  expect_load_error("header_word.txt", toy_with_line(1, "2 two 0 0"), 1, "k L scoring weighting");
  expect_load_error("k1.txt", toy_with_line(1, "1 2 0 0"), 1, "k: expected an integer in [2, 64]");
  expect_load_error("l9.txt", toy_with_line(1, "2 9 0 0"), 1, "L: expected an integer in [1, 8]");
  expect_load_error("scoring.txt", toy_with_line(1, "2 2 1 0"), 1,
                    "expected scoring 0 (L1) and weighting 0 (TF-IDF), got scoring 1 and weighting 0");
  expect_load_error("weighting.txt", toy_with_line(1, "2 2 0 3"), 1, "got scoring 0 and weighting 3");
  std::string d31 = desc_text(toy_a());
  d31.resize(d31.size() - 2);  // 31 bytes
  expect_load_error("bytes31.txt", toy_with_line(4, "1 1 " + d31 + " 0.5"), 4, "expected 35 fields");
  expect_load_error("bytes33.txt", toy_with_line(4, "1 1 0 " + desc_text(toy_a()) + " 0.5"), 4,
                    "expected 35 fields");
  std::string d256 = "0 0 0 256 " + desc_text(toy_a()).substr(8);
  expect_load_error("byte256.txt", toy_with_line(5, "1 1 " + d256 + " 1"), 5,
                    "descriptor byte 3: expected an integer in [0, 255], got \"256\"");
  expect_load_error("byte_neg.txt", toy_with_line(5, "1 1 -1 " + desc_text(toy_a()).substr(2) + " 1"), 5,
                    "descriptor byte 0");
  expect_load_error("forward.txt", toy_with_line(3, "5 0 " + desc_text(toy_b()) + " 0"), 3,
                    "expected an earlier node");
  expect_load_error("self.txt", toy_with_line(3, "2 0 " + desc_text(toy_b()) + " 0"), 3,
                    "expected an earlier node");
  expect_load_error("leaf_parent.txt", toy_with_line(6, "3 1 " + desc_text(toy_b()) + " 2"), 6, "is a leaf");
  expect_load_error("is_leaf2.txt", toy_with_line(4, "1 2 " + desc_text(toy_a()) + " 0.5"), 4,
                    "is_leaf: expected 0 or 1");
  expect_load_error("weight_neg.txt", toy_with_line(4, "1 1 " + desc_text(toy_a()) + " -0.5"), 4, "weight");
  expect_load_error("weight_nan.txt", toy_with_line(4, "1 1 " + desc_text(toy_a()) + " nan"), 4, "weight");
  expect_load_error("weight_text.txt", toy_with_line(4, "1 1 " + desc_text(toy_a()) + " 0.5x"), 4, "weight");
  expect_load_error("blank.txt", toy_with_line(4, ""), 4, "expected 35 fields");
  expect_load_error("no_words.txt", "2 2  0 0\n", 2, "no words");
  // Node 2 (line 3) is inner but nothing names it as parent.
  expect_load_error("childless.txt", toy_text().substr(0, toy_text().find("2 1 ")), 3, "has no children");
  // Three children under node 1 with k = 2.
  expect_load_error("k_children.txt", toy_text() + "1 1 " + desc_text(toy_b()) + " 1\n", 8,
                    "more than k = 2 children");
  // A third level under L = 2.
  expect_load_error("too_deep.txt", toy_with_line(1, "2 2 0 0") + "3 1 " + desc_text(toy_b()) + " 1\n", 8,
                    "is a leaf");
  expect_load_error(
      "too_deep2.txt",
      toy_with_line(4, "1 0 " + desc_text(toy_a()) + " 0") + "3 1 " + desc_text(toy_b()) + " 1\n", 8,
      "deeper than L = 2");
}

TEST(VocabularyFiles, TruncatedTextNamesTheLastLine) {
  const std::string text = toy_text();
  // Cut in the middle of the last line's descriptor (line 7).
  expect_load_error("cut.txt", text.substr(0, text.size() - 40), 7, "expected 35 fields");
}

/// The toy vocabulary in our binary format.
std::string toy_binary() {
  TempFile text("toy_bin.txt"), bin("toy_bin.bin");
  pvb::write_file(text.path, toy_text());
  Vocabulary::load(text.path).save_binary(bin.path);
  return read_bytes(bin.path);
}

TEST(VocabularyFiles, TruncatedBinaryNamesTheByte) {
  const std::string bin = toy_binary();
  ASSERT_EQ(bin.size(), 24U + 6 * 45 + 8);
  for (const std::size_t n : {std::size_t{3}, std::size_t{7}, std::size_t{8}, std::size_t{20},
                              std::size_t{24}, std::size_t{24 + 45 + 10}, bin.size() - 9, bin.size() - 1}) {
    const std::string what = n < 8    ? "expected the 8-byte magic"
                             : n < 24 ? "expected a 24-byte header"
                                      : "expected 302 bytes for 7 nodes";
    expect_load_error("cut" + std::to_string(n) + ".bin", bin.substr(0, n), 0,
                      "truncated at byte " + std::to_string(n) + ": " + what);
  }
}

TEST(VocabularyFiles, CorruptBinaryIsCaught) {
  const std::string bin = toy_binary();
  std::string flipped = bin;
  flipped[24 + 45 * 2 + 5 + 7] ^= 0x10;  // a bit of node 3's descriptor
  expect_load_error("flipped.bin", flipped, 0, "byte 294: checksum mismatch");
  std::string weight = bin;
  weight[24 + 45 * 3 + 37 + 2] ^= 0x01;  // a bit of node 4's weight
  expect_load_error("weight.bin", weight, 0, "checksum mismatch");
  expect_load_error("longer.bin", bin + "x", 0, "byte 302: unexpected data after the checksum");
  std::string version = bin;
  version[6] = '2';
  expect_load_error("version.bin", version, 0, "byte 0: expected the magic");
  std::string k = bin;
  k[8] = 1;
  expect_load_error("k.bin", k, 0, "byte 8: k: expected an integer in [2, 64], got 1");
  std::string nodes = bin;
  nodes[16] = 8;  // 8 nodes: the size no longer matches
  expect_load_error("nodes.bin", nodes, 0, "truncated at byte 302: expected 347 bytes for 8 nodes");
}

}  // namespace
