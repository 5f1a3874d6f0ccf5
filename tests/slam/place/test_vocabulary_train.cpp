// Training: known clusters are recovered (one and two levels), the trivial
// and degenerate splits, IDF weights, determinism, bad parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "synthetic.hpp"

namespace {

using namespace pvb::slam::place;
using namespace pvb::slam::place::test;

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Descriptors of a cluster: its centre with 0..max_flips random bits flipped.
std::vector<Desc> noisy_copies(const Desc& centre, int n, int max_flips, std::mt19937_64& rng) {
  std::vector<Desc> out;
  for (int i = 0; i < n; ++i)
    out.push_back(flip_bits(centre, static_cast<int>(rng() % (max_flips + 1)), rng));
  return out;
}

/// The word whose centre is nearest to `d`, by brute force over the words.
WordId nearest_word(const Vocabulary& voc, const Desc& d, int* dist) {
  WordId best = 0;
  *dist = 257;
  for (WordId w = 0; w < voc.size(); ++w) {
    const int dw = distance(d, from_ptr(voc.centre(voc.word_node(w))));
    if (dw < *dist) {
      *dist = dw;
      best = w;
    }
  }
  return best;
}

TEST(VocabularyTrain, OneLevelRecoversFourClusters) {
  std::mt19937_64 rng(11);
  const std::vector<Desc> centres = far_centres(4, 90, rng);
  // 20 images of 40 descriptors, each image from one cluster: every word is
  // in 5 of 20 images, IDF ln 4.
  std::vector<cv::Mat> images;
  std::vector<std::vector<Desc>> per_image;
  for (int i = 0; i < 20; ++i) {
    per_image.push_back(noisy_copies(centres[i % 4], 40, 10, rng));
    images.push_back(to_mat(per_image.back()));
  }
  TrainParams p;
  p.k = 4;
  p.levels = 1;
  TrainReport report;
  const Vocabulary voc = Vocabulary::train(images, p, &report);
  ASSERT_EQ(voc.size(), 4U);
  EXPECT_EQ(voc.node_count(), 5U);
  EXPECT_EQ(report.images, 20U);
  EXPECT_EQ(report.descriptors, 800U);
  EXPECT_EQ(report.words, 4U);
  EXPECT_EQ(report.nodes, 5U);
  // Each true centre has its own word, within 2 bits.
  std::map<WordId, int> word_of_cluster;
  for (int c = 0; c < 4; ++c) {
    int dist = 0;
    word_of_cluster[nearest_word(voc, centres[c], &dist)] = c;
    EXPECT_LE(dist, 2) << "cluster " << c;
  }
  ASSERT_EQ(word_of_cluster.size(), 4U);
  for (WordId w = 0; w < 4; ++w) EXPECT_NEAR(voc.word_weight(w), std::log(4.0), 1e-12);
  for (int i = 0; i < 20; ++i) {
    int dist = 0;
    const WordId expected = nearest_word(voc, centres[i % 4], &dist);
    for (const Desc& d : per_image[i]) EXPECT_EQ(voc.word_of(d.data()), expected);
  }
}

TEST(VocabularyTrain, TwoLevelsRecoverNineClustersInThreeGroups) {
  std::mt19937_64 rng(5);
  const std::vector<Desc> supers = far_centres(3, 90, rng);
  std::vector<Desc> subs;  // sub-cluster s belongs to super s / 3
  for (int s = 0; s < 9; ++s) subs.push_back(flip_bits(supers[s / 3], 16, rng));
  // 36 images of 25 descriptors, each from one sub-cluster: IDF ln 9.
  std::vector<cv::Mat> images;
  std::vector<std::vector<Desc>> per_image;
  for (int i = 0; i < 36; ++i) {
    per_image.push_back(noisy_copies(subs[i % 9], 25, 4, rng));
    images.push_back(to_mat(per_image.back()));
  }
  TrainParams p;
  p.k = 3;
  p.levels = 2;
  const Vocabulary voc = Vocabulary::train(images, p);
  ASSERT_EQ(voc.size(), 9U);
  ASSERT_EQ(voc.children(0).size(), 3U);
  for (const NodeId n : voc.children(0)) EXPECT_EQ(voc.children(n).size(), 3U);
  std::map<WordId, int> sub_of_word;
  std::map<NodeId, int> super_of_node;
  for (int s = 0; s < 9; ++s) {
    int dist = 0;
    const WordId w = nearest_word(voc, subs[s], &dist);
    EXPECT_LE(dist, 2) << "sub-cluster " << s;
    sub_of_word[w] = s;
    // The word's parent stands for the super-cluster: one node per super.
    NodeId level1 = 0;
    voc.word_of(subs[s].data(), nullptr, &level1, 1);
    const auto [it, inserted] = super_of_node.emplace(level1, s / 3);
    EXPECT_EQ(it->second, s / 3) << "sub-cluster " << s << " under another super-cluster's node";
  }
  EXPECT_EQ(sub_of_word.size(), 9U);
  EXPECT_EQ(super_of_node.size(), 3U);
  for (WordId w = 0; w < 9; ++w) EXPECT_NEAR(voc.word_weight(w), std::log(9.0), 1e-12);
  for (int i = 0; i < 36; ++i) {
    for (const Desc& d : per_image[i]) EXPECT_EQ(sub_of_word.at(voc.word_of(d.data())), i % 9);
  }
}

TEST(VocabularyTrain, ABitSetInHalfTheMembersIsSetInTheCentre) {
  // Two pairs far apart; in each pair the two descriptors differ in one
  // bit.  DBoW2's binary median sets a bit held by at least half of the
  // members, so each centre is the member with the bit set.
  std::mt19937_64 rng(6);
  const std::vector<Desc> c = far_centres(2, 100, rng);
  std::vector<Desc> with_bit(c), without_bit(c);
  with_bit[0][0] |= 0x01;
  without_bit[0][0] &= 0xFE;
  with_bit[1][31] |= 0x80;
  without_bit[1][31] &= 0x7F;
  TrainParams p;
  p.k = 2;
  p.levels = 1;
  const Vocabulary voc =
      Vocabulary::train({to_mat({without_bit[0], with_bit[0], without_bit[1], with_bit[1]})}, p);
  ASSERT_EQ(voc.size(), 2U);
  for (int i = 0; i < 2; ++i) {
    const WordId w = voc.word_of(c[i].data());
    EXPECT_EQ(from_ptr(voc.centre(voc.word_node(w))), with_bit[i]) << "pair " << i;
  }
}

TEST(VocabularyTrain, AtMostKDescriptorsEachMakeAChild) {
  std::mt19937_64 rng(3);
  const std::vector<Desc> three = far_centres(3, 60, rng);
  TrainParams p;
  p.k = 4;
  p.levels = 3;
  const Vocabulary voc = Vocabulary::train({to_mat(three)}, p);
  ASSERT_EQ(voc.size(), 3U);
  ASSERT_EQ(voc.node_count(), 4U);  // a node with one descriptor is not split
  for (WordId w = 0; w < 3; ++w) {
    EXPECT_EQ(voc.word_node(w), w + 1);
    EXPECT_EQ(from_ptr(voc.centre(w + 1)), three[w]);
    EXPECT_EQ(voc.word_of(three[w].data()), w);
    EXPECT_EQ(voc.word_weight(w), 0.0);  // one image: ln(1 / 1)
  }
}

TEST(VocabularyTrain, IdenticalDescriptorsMakeAChainOfOneChild) {
  std::mt19937_64 rng(4);
  const Desc d = random_desc(rng);
  TrainParams p;
  p.k = 2;
  p.levels = 3;
  const Vocabulary voc = Vocabulary::train({to_mat(std::vector<Desc>(7, d))}, p);
  EXPECT_EQ(voc.size(), 1U);
  EXPECT_EQ(voc.node_count(), 4U);  // root -> 1 -> 2 -> 3 (the word)
  EXPECT_EQ(voc.word_node(0), 3U);
  EXPECT_EQ(from_ptr(voc.centre(3)), d);
}

TEST(VocabularyTrain, NodesAreNumberedBreadthFirst) {
  std::mt19937_64 rng(8);
  std::vector<Desc> all;
  for (int i = 0; i < 400; ++i) all.push_back(random_desc(rng));
  TrainParams p;
  p.k = 3;
  p.levels = 3;
  const Vocabulary voc = Vocabulary::train({to_mat(all)}, p);
  // Breadth first: visiting the tree level by level, children in order,
  // meets the ids 1, 2, 3, ... in turn.
  std::vector<NodeId> queue{0};
  NodeId expected = 1;
  for (std::size_t i = 0; i < queue.size(); ++i) {
    for (const NodeId c : voc.children(queue[i])) {
      EXPECT_EQ(c, expected++);
      queue.push_back(c);
    }
  }
  EXPECT_EQ(expected, voc.node_count());
  EXPECT_EQ(voc.size(), 27U);  // 400 random descriptors fill every node
}

TEST(VocabularyTrain, SameSeedGivesTheSameFileAnotherSeedAnother) {
  std::mt19937_64 rng(21);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 40; ++i) {
    std::vector<Desc> img;
    for (int j = 0; j < 100; ++j) img.push_back(random_desc(rng));
    images.push_back(to_mat(img));
  }
  TrainParams p;
  p.k = 5;
  p.levels = 3;
  p.seed = 7;
  const std::string a = temp_path("det_a.bin"), b = temp_path("det_b.bin"), c = temp_path("det_c.bin");
  Vocabulary::train(images, p).save_binary(a);
  Vocabulary::train(images, p).save_binary(b);
  p.seed = 8;
  Vocabulary::train(images, p).save_binary(c);
  EXPECT_EQ(file_bytes(a), file_bytes(b));
  EXPECT_NE(file_bytes(a), file_bytes(c));
  for (const auto& f : {a, b, c}) std::remove(f.c_str());
}

TEST(VocabularyTrain, EmptyImagesAreSkippedAndNotCounted) {
  std::mt19937_64 rng(2);
  const std::vector<Desc> centres = far_centres(2, 90, rng);
  // Two non-empty images, one per cluster, and three empty ones: N = 2.
  const std::vector<cv::Mat> images{cv::Mat(), to_mat(noisy_copies(centres[0], 10, 3, rng)), cv::Mat(),
                                    to_mat(noisy_copies(centres[1], 10, 3, rng)), cv::Mat(0, 32, CV_8U)};
  TrainParams p;
  p.k = 2;
  p.levels = 1;
  TrainReport report;
  const Vocabulary voc = Vocabulary::train(images, p, &report);
  EXPECT_EQ(report.images, 2U);
  ASSERT_EQ(voc.size(), 2U);
  for (WordId w = 0; w < 2; ++w) EXPECT_NEAR(voc.word_weight(w), std::log(2.0), 1e-12);
}

TEST(VocabularyTrain, BadParametersAndDescriptorsAreConfigErrors) {
  std::mt19937_64 rng(1);
  const cv::Mat one = to_mat({random_desc(rng), random_desc(rng), random_desc(rng)});
  auto expect_error = [&](const std::vector<cv::Mat>& images, TrainParams p, const std::string& key) {
    try {
      Vocabulary::train(images, p);
      ADD_FAILURE() << "no error for " << key;
    } catch (const pvb::ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  TrainParams p;
  p.k = 1;
  expect_error({one}, p, "k");
  p.k = 65;
  expect_error({one}, p, "k");
  p = {};
  p.levels = 0;
  expect_error({one}, p, "levels");
  p.levels = 9;
  expect_error({one}, p, "levels");
  p = {};
  p.max_iterations = -1;
  expect_error({one}, p, "max_iterations");
  expect_error({}, TrainParams{}, "descriptors");
  expect_error({cv::Mat()}, TrainParams{}, "descriptors");
  expect_error({one, cv::Mat(3, 32, CV_32F)}, TrainParams{}, "descriptors of image 1");
  expect_error({cv::Mat(3, 31, CV_8U)}, TrainParams{}, "descriptors of image 0");
}

}  // namespace
