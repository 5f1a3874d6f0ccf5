// transform, word_of and score on the toy vocabulary of synthetic.hpp,
// against numbers worked out by hand, and the direct index on a trained
// two-level tree.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "synthetic.hpp"

namespace {

using namespace pvb::slam::place;
using namespace pvb::slam::place::test;

Vocabulary load_text(const std::string& name, const std::string& text) {
  const std::string path = temp_path(name);
  pvb::write_file(path, text);
  Vocabulary voc = Vocabulary::load(path);
  std::remove(path.c_str());
  return voc;
}

/// The toy's four query descriptors and their words:
///   q0 = A (0 bits from A, 256 from B; then 0 from A1, 32 from A2)  -> word 0
///   q1 = A2 (32 from A, 224 from B; then 32 from A1, 0 from A2)     -> word 1
///   q2 = B                                                           -> word 2
///   q3 = B2 (224 from A, 32 from B; 32 from B1, 0 from B2)           -> word 3
TEST(VocabularyTransform, ToyWordsAndWeights) {
  const Vocabulary voc = load_text("toy_words.txt", toy_text());
  ASSERT_EQ(voc.size(), 4U);
  EXPECT_EQ(voc.k(), 2);
  EXPECT_EQ(voc.levels(), 2);
  EXPECT_EQ(voc.node_count(), 7U);
  const std::vector<Desc> q{toy_a(), toy_a2(), toy_b(), toy_b2()};
  const double idf[] = {0.5, 1.0, 2.0, 0.0};
  for (WordId w = 0; w < 4; ++w) {
    double weight = -1;
    NodeId parent = 99;
    EXPECT_EQ(voc.word_of(q[w].data(), &weight, &parent, 1), w);
    EXPECT_EQ(weight, idf[w]);
    EXPECT_EQ(parent, w < 2 ? 1U : 2U);
    EXPECT_EQ(voc.word_node(w), w + 3);
  }
}

TEST(VocabularyTransform, TiesGoToTheFirstChild) {
  const Vocabulary voc = load_text("toy_ties.txt", toy_text());
  // Bytes 0-15 set: 128 bits from both A and B -> node 1 (A); then 128
  // from A1 and 96 from A2 -> word 1.
  Desc half{};
  for (int i = 0; i < 16; ++i) half[i] = 255;
  EXPECT_EQ(voc.word_of(half.data()), 1U);
  // Bytes 0-1 set: 16 bits from A (nearer than B) and 16 from both A1 and
  // A2 -> word 0, the first child.
  Desc two{};
  two[0] = two[1] = 255;
  EXPECT_EQ(voc.word_of(two.data()), 0U);
}

// Image a = {q0, q0, q1, q3}: word 0 gets 0.5 + 0.5, word 1 gets 1, word 3
// (IDF 0) is skipped; L1 norm 2 -> a = {0: 0.5, 1: 0.5}.
// Image b = {q0, q2, q2}: word 0 gets 0.5, word 2 gets 2 + 2; norm 4.5 ->
// b = {0: 1/9, 2: 8/9}.
// score(a, b) = -0.5 (|0.5 - 1/9| - 0.5 - 1/9) = 1/9, which is also
// 1 - 0.5 |a - b|_1 = 1 - 0.5 (7/18 + 1/2 + 8/9) = 1/9.
TEST(VocabularyTransform, ToyTfIdfAndL1Score) {
  const Vocabulary voc = load_text("toy_score.txt", toy_text());
  BowVector a, b;
  voc.transform(to_mat({toy_a(), toy_a(), toy_a2(), toy_b2()}), &a);
  voc.transform(to_mat({toy_a(), toy_b(), toy_b()}), &b);
  ASSERT_EQ(a.size(), 2U);
  EXPECT_EQ(a[0].first, 0U);
  EXPECT_DOUBLE_EQ(a[0].second, 0.5);
  EXPECT_EQ(a[1].first, 1U);
  EXPECT_DOUBLE_EQ(a[1].second, 0.5);
  ASSERT_EQ(b.size(), 2U);
  EXPECT_EQ(b[0].first, 0U);
  EXPECT_DOUBLE_EQ(b[0].second, 1.0 / 9.0);
  EXPECT_EQ(b[1].first, 2U);
  EXPECT_DOUBLE_EQ(b[1].second, 8.0 / 9.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score(a, b), 1.0 / 9.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score(b, a), 1.0 / 9.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score(a, a), 1.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score(a, {{2, 1.0}}), 0.0);
  EXPECT_DOUBLE_EQ(Vocabulary::score({}, a), 0.0);
}

TEST(VocabularyTransform, ToyDirectIndex) {
  const Vocabulary voc = load_text("toy_fv.txt", toy_text());
  const cv::Mat img = to_mat({toy_a(), toy_a(), toy_a2(), toy_b2(), toy_b()});
  BowVector bow;
  FeatureVector fv;
  voc.transform(img, &bow, &fv, 1);  // depth L - 1 = 1: nodes 1 and 2
  // Feature 3 (word 3, IDF 0) is in neither the bag nor the direct index.
  EXPECT_EQ(fv, (FeatureVector{{1, {0, 1, 2}}, {2, {4}}}));
  voc.transform(img, &bow, &fv, 0);  // the leaves
  EXPECT_EQ(fv, (FeatureVector{{3, {0, 1}}, {4, {2}}, {5, {4}}}));
  voc.transform(img, &bow, &fv, 2);  // depth 0: the root
  EXPECT_EQ(fv, (FeatureVector{{0, {0, 1, 2, 4}}}));
  voc.transform(img, nullptr, &fv, 7);  // beyond the root: still the root
  EXPECT_EQ(fv, (FeatureVector{{0, {0, 1, 2, 4}}}));
}

TEST(VocabularyTransform, LeafAboveTheIndexDepthIndexesItself) {
  // Root -> node 1 (inner, A), node 2 (leaf, B); node 1 -> 3 (A), 4 (A2).
  // Words in node order: node 2 is word 0, nodes 3 and 4 words 1 and 2.
  const std::string text =
      "2 2  0 0\n"
      "0 0 " +
      desc_text(toy_a()) +
      " 0\n"
      "0 1 " +
      desc_text(toy_b()) +
      " 1\n"
      "1 1 " +
      desc_text(toy_a()) +
      " 1\n"
      "1 1 " +
      desc_text(toy_a2()) + " 1\n";
  const Vocabulary voc = load_text("uneven.txt", text);
  ASSERT_EQ(voc.size(), 3U);
  EXPECT_EQ(voc.word_node(0), 2U);
  EXPECT_EQ(voc.word_of(toy_b().data()), 0U);
  EXPECT_EQ(voc.word_of(toy_a2().data()), 2U);
  BowVector bow;
  FeatureVector fv;
  voc.transform(to_mat({toy_b(), toy_a(), toy_a2()}), &bow, &fv, 0);  // depth 2 wanted
  EXPECT_EQ(fv, (FeatureVector{{2, {0}}, {3, {1}}, {4, {2}}}));
  EXPECT_EQ(bow, (BowVector{{0, 1.0 / 3}, {1, 1.0 / 3}, {2, 1.0 / 3}}));
}

TEST(VocabularyTransform, TrainedDirectIndexGroupsByTheNodeAboveTheWord) {
  std::mt19937_64 rng(9);
  const std::vector<Desc> supers = far_centres(3, 90, rng);
  std::vector<Desc> subs;  // sub-cluster s belongs to super s / 3
  for (int s = 0; s < 9; ++s) subs.push_back(flip_bits(supers[s / 3], 16, rng));
  std::vector<cv::Mat> images;
  for (int i = 0; i < 18; ++i) {  // image i from sub-cluster i % 9
    std::vector<Desc> img;
    for (int j = 0; j < 20; ++j) img.push_back(flip_bits(subs[i % 9], static_cast<int>(rng() % 4), rng));
    images.push_back(to_mat(img));
  }
  TrainParams p;
  p.k = 3;
  p.levels = 2;
  const Vocabulary voc = Vocabulary::train(images, p);
  cv::Mat query;
  cv::vconcat(std::vector<cv::Mat>{images[0], images[4], images[8], images[10]}, query);
  BowVector bow;
  FeatureVector fv;
  voc.transform(query, &bow, &fv, 1);
  std::size_t indexed = 0;
  for (const auto& [node, features] : fv) {
    EXPECT_EQ(std::count(voc.children(0).begin(), voc.children(0).end(), node), 1) << "node " << node;
    EXPECT_TRUE(std::is_sorted(features.begin(), features.end()));
    for (const std::uint32_t f : features) {
      const WordId w = voc.word_of(query.ptr(static_cast<int>(f)));
      const std::vector<NodeId>& under = voc.children(node);
      EXPECT_EQ(std::count(under.begin(), under.end(), voc.word_node(w)), 1) << "feature " << f;
    }
    indexed += features.size();
  }
  EXPECT_EQ(indexed, static_cast<std::size_t>(query.rows));
  EXPECT_EQ(fv.size(), 3U);  // images 0, 4, 8 (and 10) span the three super-clusters
  double sum = 0;
  for (const auto& [w, v] : bow) sum += v;
  EXPECT_NEAR(sum, 1.0, 1e-12);
}

TEST(VocabularyTransform, SortedArraysHoldWhatMapsPerWordAndNodeHeld) {
  // Many descriptors per word: the weights are summed per word in row
  // order, as a std::map's v[word] += weight did, so the bags are the same
  // doubles, not merely close.
  std::mt19937_64 rng(21);
  const std::vector<Desc> centres = far_centres(6, 90, rng);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 12; ++i) {
    std::vector<Desc> img;
    for (int j = 0; j < 30; ++j) img.push_back(flip_bits(centres[(i + j) % 6], static_cast<int>(rng() % 20), rng));
    images.push_back(to_mat(img));
  }
  TrainParams p;
  p.k = 3;
  p.levels = 3;
  const Vocabulary voc = Vocabulary::train(images, p);
  for (const cv::Mat& img : images) {
    std::map<WordId, double> words;
    std::map<NodeId, std::vector<std::uint32_t>> nodes;
    for (int r = 0; r < img.rows; ++r) {
      double weight = 0;
      NodeId node = 0;
      const WordId w = voc.word_of(img.ptr(r), &weight, &node, 1);
      if (weight <= 0) continue;
      words[w] += weight;
      nodes[node].push_back(static_cast<std::uint32_t>(r));
    }
    double norm = 0;
    for (const auto& [w, v] : words) norm += std::fabs(v);
    for (auto& [w, v] : words) v /= norm;
    BowVector bow;
    FeatureVector fv;
    voc.transform(img, &bow, &fv, 1);
    EXPECT_EQ(bow, BowVector(words.begin(), words.end()));
    EXPECT_EQ(fv, FeatureVector(nodes.begin(), nodes.end()));
    EXPECT_LT(bow.size(), static_cast<std::size_t>(img.rows));  // words do repeat
  }
}

TEST(VocabularyTransform, EmptyInputGivesEmptyVectorsAndWrongTypeThrows) {
  const Vocabulary voc = load_text("toy_empty.txt", toy_text());
  BowVector bow{{1, 1.0}};
  FeatureVector fv{{1, {0}}};
  voc.transform(cv::Mat(), &bow, &fv);
  EXPECT_TRUE(bow.empty());
  EXPECT_TRUE(fv.empty());
  EXPECT_THROW(voc.transform(cv::Mat(2, 32, CV_32F), &bow), pvb::ConfigError);
  Vocabulary none;
  none.transform(to_mat({toy_a()}), &bow, &fv);
  EXPECT_TRUE(bow.empty());
}

}  // namespace
