// Keyframe database: inverted index, candidates' filters and order.
#include <gtest/gtest.h>

#include <climits>
#include <random>
#include <set>
#include <stdexcept>

#include "pvb/slam/place/database.hpp"

namespace {

using namespace pvb::slam::place;

std::vector<std::uint64_t> ids(const std::vector<Candidate>& c) {
  std::vector<std::uint64_t> out;
  for (const Candidate& x : c) out.push_back(x.id);
  return out;
}

// The query q = {1: .25, 2: .25, 3: .25, 4: .25}; with each keyframe's
// common words and L1 score (the sum of min(q_i, k_i) over common words):
//   kf 10 = q                           4 words, score 1
//   kf 11 = {1: .5, 2: .5}              2 words, score .5
//   kf 12 = {1: .25, 2: .25, 3: .5}     3 words, score .75
//   kf 13 = {5: 1}                      0 words
//   kf 14 = {1: .1, 2: .1, 3: .1, 9: .7} 3 words, score .3
//   kf  9 = kf 12                       3 words, score .75 (ties with 12: id order)
const BowVector kQuery{{1, .25}, {2, .25}, {3, .25}, {4, .25}};

void fill(Database& db) {
  db.add(10, kQuery);
  db.add(11, {{1, .5}, {2, .5}});
  db.add(12, {{1, .25}, {2, .25}, {3, .5}});
  db.add(13, {{5, 1.0}});
  db.add(14, {{1, .1}, {2, .1}, {3, .1}, {9, .7}});
  db.add(9, {{1, .25}, {2, .25}, {3, .5}});
}

TEST(Database, QueryScoresAndOrders) {
  Database db;
  fill(db);
  EXPECT_EQ(db.size(), 6U);
  // min_common_ratio 0: every keyframe sharing a word.
  const std::vector<Candidate> all = db.query(kQuery, 0.0, 0.0);
  EXPECT_EQ(ids(all), (std::vector<std::uint64_t>{10, 9, 12, 11, 14}));
  EXPECT_DOUBLE_EQ(all[0].score, 1.0);
  EXPECT_EQ(all[0].common_words, 4);
  EXPECT_DOUBLE_EQ(all[1].score, 0.75);
  EXPECT_EQ(all[1].common_words, 3);
  EXPECT_DOUBLE_EQ(all[3].score, 0.5);
  EXPECT_EQ(all[3].common_words, 2);
  EXPECT_NEAR(all[4].score, 0.3, 1e-12);
}

TEST(Database, MinCommonRatioKeepsThoseSharingEnoughWords) {
  Database db;
  fill(db);
  // Largest count 4: 0.8 x 4 = 3.2 keeps only kf 10; 0.75 x 4 = 3 adds the
  // three-word ones; 0.5 x 4 = 2 adds kf 11.
  EXPECT_EQ(ids(db.query(kQuery, 0.0)), (std::vector<std::uint64_t>{10}));
  EXPECT_EQ(ids(db.query(kQuery, 0.0, 0.75)), (std::vector<std::uint64_t>{10, 9, 12, 14}));
  EXPECT_EQ(ids(db.query(kQuery, 0.0, 0.5)), (std::vector<std::uint64_t>{10, 9, 12, 11, 14}));
}

TEST(Database, MinScoreFilters) {
  Database db;
  fill(db);
  EXPECT_EQ(ids(db.query(kQuery, 0.75, 0.0)), (std::vector<std::uint64_t>{10, 9, 12}));
  EXPECT_EQ(ids(db.query(kQuery, 0.76, 0.0)), (std::vector<std::uint64_t>{10}));
  EXPECT_TRUE(db.query(kQuery, 1.01, 0.0).empty());
}

TEST(Database, SkippedKeyframesAreNeitherCandidatesNorCounted) {
  Database db;
  fill(db);
  int calls = 0;
  const auto skip = [&](std::uint64_t id) {
    ++calls;
    return id == 10;
  };
  // Without kf 10 the largest count is 3: at 0.8 the three-word keyframes.
  EXPECT_EQ(ids(db.query(kQuery, 0.0, 0.8, skip)), (std::vector<std::uint64_t>{9, 12, 14}));
  // Asked down the counts until 0.8 x the largest not skipped: 10 (4 words,
  // skipped), then 9, 12 and 14 (3 words); never 11 (2 words, below 2.4).
  EXPECT_EQ(calls, 4);
}

TEST(Database, QueryAboveTakesTheLeastScoreOfTheReferenceKeyframes) {
  Database db;
  fill(db);
  const auto skip = [](std::uint64_t id) { return id == 11 || id == 14; };  // the "covisibles"
  // The least of kf 11's 0.5 and kf 14's 0.3 is 0.3: every other keyframe
  // sharing a word qualifies; with kf 11 alone, 0.5.
  const auto low = db.query_above(kQuery, {11, 14}, 0.0, skip);
  EXPECT_EQ(ids(low), (std::vector<std::uint64_t>{10, 9, 12}));
  EXPECT_EQ(ids(db.query_above(kQuery, {11}, 0.0, skip)), ids(db.query(kQuery, 0.5, 0.0, skip)));
  // A reference keyframe sharing no word scores 0; none at all leaves 1.
  EXPECT_EQ(ids(db.query_above(kQuery, {13}, 0.0, skip)), ids(db.query(kQuery, 0.0, 0.0, skip)));
  EXPECT_EQ(ids(db.query_above(kQuery, {}, 0.0, skip)), (std::vector<std::uint64_t>{10}));
  // The same doubles as Vocabulary::score of the two bags.
  for (const Candidate& c : low) EXPECT_EQ(c.score, Vocabulary::score(kQuery, db.bag(c.id)));
}

TEST(Database, EraseAndReplaceUpdateTheIndex) {
  Database db;
  fill(db);
  EXPECT_EQ(db.keyframes_with(1), (std::vector<std::uint64_t>{9, 10, 11, 12, 14}));
  EXPECT_EQ(db.keyframes_with(5), (std::vector<std::uint64_t>{13}));
  EXPECT_TRUE(db.keyframes_with(7).empty());
  db.erase(10);
  db.erase(10);   // absent: no-op
  db.erase(100);  // never added
  EXPECT_EQ(db.size(), 5U);
  EXPECT_EQ(db.keyframes_with(1), (std::vector<std::uint64_t>{9, 11, 12, 14}));
  EXPECT_TRUE(db.keyframes_with(4).empty());
  EXPECT_EQ(ids(db.query(kQuery, 0.0, 0.0)), (std::vector<std::uint64_t>{9, 12, 11, 14}));
  // kf 13 replaced by words 4 and 6: it leaves word 5's list and joins 4's and 6's.
  db.add(13, {{4, .5}, {6, .5}});
  EXPECT_EQ(db.size(), 5U);
  EXPECT_TRUE(db.keyframes_with(5).empty());
  EXPECT_EQ(db.keyframes_with(4), (std::vector<std::uint64_t>{13}));
  EXPECT_EQ(db.keyframes_with(6), (std::vector<std::uint64_t>{13}));
  const std::vector<Candidate> c = db.query(kQuery, 0.0, 0.0);
  EXPECT_EQ(ids(c), (std::vector<std::uint64_t>{9, 12, 11, 14, 13}));
  EXPECT_DOUBLE_EQ(c.back().score, 0.25);
}

TEST(Database, IdsStayAscendingWhateverTheAddOrder) {
  Database db;
  for (const std::uint64_t id : {5, 1, 9, 3, 7}) db.add(id, {{2, 1.0}});
  EXPECT_EQ(db.keyframes_with(2), (std::vector<std::uint64_t>{1, 3, 5, 7, 9}));
  // Equal scores: ascending ids.
  EXPECT_EQ(ids(db.query({{2, 1.0}}, 0.0)), (std::vector<std::uint64_t>{1, 3, 5, 7, 9}));
  EXPECT_TRUE(db.query({{3, 1.0}}, 0.0).empty());
  EXPECT_TRUE(db.query({}, 0.0).empty());
}

TEST(Database, BagIsWhatWasAddedFromTheListsWeights) {
  Database db;
  fill(db);
  EXPECT_EQ(db.bag(10), kQuery);
  EXPECT_EQ(db.bag(14), (BowVector{{1, .1}, {2, .1}, {3, .1}, {9, .7}}));
  EXPECT_TRUE(db.bag(99).empty());
  db.add(14, {{2, .6}, {7, .4}});  // replaced: the old words go
  EXPECT_EQ(db.bag(14), (BowVector{{2, .6}, {7, .4}}));
  EXPECT_EQ(db.keyframes_with(9), std::vector<std::uint64_t>{});
  db.erase(12);
  EXPECT_TRUE(db.bag(12).empty());
  EXPECT_EQ(db.bag(9), (BowVector{{1, .25}, {2, .25}, {3, .5}}));
  EXPECT_GT(db.memory_bytes(), 0U);
}

TEST(Database, LongListsGrowAndShrinkInOrder) {
  // 100 keyframes under word 3, added out of order: the list's buffer grows
  // past several capacities and stays in ascending ids; erasing all but one
  // frees them, and the emptied word leaves the counts.
  Database db;
  std::vector<std::uint64_t> added;
  for (std::uint64_t k = 0; k < 100; ++k) added.push_back((k * 37) % 100);
  for (std::uint64_t id : added) db.add(id, {{3, 0.5}, {1000 + id, 0.5}});
  std::vector<std::uint64_t> all(100);
  for (std::uint64_t k = 0; k < 100; ++k) all[k] = k;
  EXPECT_EQ(db.keyframes_with(3), all);
  EXPECT_EQ(db.counts().keyframes, 100U);
  EXPECT_EQ(db.counts().words, 101U);
  EXPECT_EQ(db.counts().postings, 200U);
  const std::size_t full = db.memory_bytes();
  for (std::uint64_t id = 0; id < 99; ++id) db.erase(id);
  EXPECT_EQ(db.keyframes_with(3), (std::vector<std::uint64_t>{99}));
  EXPECT_EQ(db.bag(99), (BowVector{{3, 0.5}, {1099, 0.5}}));
  EXPECT_EQ(db.counts().words, 2U);
  EXPECT_LT(db.memory_bytes(), full);
  db.erase(99);
  EXPECT_EQ(db.counts().words, 0U);
  EXPECT_TRUE(db.query({{3, 1.0}}, 0.0).empty());
}

TEST(Database, APostingCostsItsTwelveBytesAndLittleMore) {
  // 400 keyframes of 900 words each drawn from 40,000 (about 9 keyframes a
  // word, as on a plant aisle with the default vocabulary), after the list
  // heads are made: the 12-byte postings, their buffers' slack and each
  // keyframe's 4-byte word list: 22.1 bytes a posting.  A hash-map node
  // and a std::vector of 16-byte postings per word took 33.1 on this input.
  Database db;
  db.reserve(0, 40000);
  const std::size_t heads = db.memory_bytes();
  std::mt19937 rng(7);
  std::uniform_int_distribution<WordId> word(0, 39999);
  std::size_t postings = 0;
  for (std::uint64_t id = 0; id < 400; ++id) {
    std::set<WordId> words;
    while (words.size() < 900) words.insert(word(rng));
    BowVector bow;
    for (WordId w : words) bow.emplace_back(w, 1.0 / 900);
    db.add(id, bow);
    postings += bow.size();
  }
  EXPECT_EQ(db.counts().postings, postings);
  const double per_posting = static_cast<double>(db.memory_bytes() - heads) / static_cast<double>(postings);
  EXPECT_GT(per_posting, 16.0);  // 12 + 4 at the least
  EXPECT_LT(per_posting, 24.0);
}

TEST(Database, AQueryLeftByAThrowingSkipDoesNotCountInTheNext) {
  Database db;
  fill(db);
  const auto throws = [](std::uint64_t id) -> bool {
    if (id == 12) throw std::runtime_error("skip failed");
    return false;
  };
  EXPECT_THROW(db.query(kQuery, 0.0, 0.0, throws), std::runtime_error);
  const std::vector<Candidate> c = db.query(kQuery, 0.0, 0.0);
  EXPECT_EQ(ids(c), (std::vector<std::uint64_t>{10, 9, 12, 11, 14}));
  EXPECT_DOUBLE_EQ(c[0].score, 1.0);
  EXPECT_EQ(c[0].common_words, 4);
}

TEST(Database, KeyframeIdsAbove32BitsAreRefused) {
  Database db;
  db.add(UINT32_MAX, {{1, 1.0}});
  EXPECT_EQ(db.keyframes_with(1), (std::vector<std::uint64_t>{UINT32_MAX}));
  EXPECT_THROW(db.add(std::uint64_t{UINT32_MAX} + 1, {{1, 1.0}}), std::out_of_range);
  EXPECT_EQ(db.size(), 1U);
}

}  // namespace
