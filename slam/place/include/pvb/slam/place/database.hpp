#pragma once
// The keyframe database: an inverted index from words to the keyframes
// (by id) whose bag of words holds them, with the word's weight in each
// (the score is summed while the lists are walked), and each keyframe's
// words kept for replacing or erasing it.  The weights are kept once, in
// the lists: bag() puts a keyframe's bag back together from them.  The first two steps of ORB-SLAM2's DetectLoopCandidates /
// DetectRelocalizationCandidates: keyframes sharing words with a query,
// those sharing at least `min_common_ratio` of the most shared words,
// scored; covisibility accumulation is the caller's (it owns the graph).
// Thread-safe: every member takes an internal mutex.
#include <cstdint>
#include <functional>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "pvb/slam/place/vocabulary.hpp"

namespace pvb::slam::place {

struct Candidate {
  std::uint64_t id = 0;  ///< keyframe id
  int common_words = 0;  ///< words shared with the query
  double score = 0;      ///< Vocabulary::score(query, keyframe's bag)
};

class Database {
 public:
  /// One keyframe under a word, with the word's weight in its bag: query()
  /// scores while it walks the lists, as DBoW2's database does, instead of
  /// merging two bags per keyframe.  12 bytes: keyframe ids up to 2^32 - 1.
  /// Packed: read `weight` by value, never bind a reference to it.
#pragma pack(push, 4)
  struct Posting {
    std::uint32_t id;
    double weight;
  };
#pragma pack(pop)
  Database() = default;
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;
  /// Adds (or replaces) a keyframe's bag.  Throws std::out_of_range for an
  /// id above 2^32 - 1.
  void add(std::uint64_t id, const BowVector& bow);
  /// Makes room for this many keyframes and words (a map's worth, added at
  /// once; words: the vocabulary's size, or the largest word id + 1).
  void reserve(std::size_t keyframes, std::size_t words);
  /// Removes a keyframe (no-op when absent).
  void erase(std::uint64_t id);
  std::size_t size() const;
  /// The keyframes sharing at least one word with `query`, except those for
  /// which `skip(id)` is true; of those, the ones sharing at least
  /// min_common_ratio x the largest count, scored, and kept when score >=
  /// min_score.  Ordered by descending score, then ascending id
  /// (deterministic).  `skip` is asked at most once per keyframe, only of
  /// keyframes that share enough words to be candidates (from the most
  /// shared down), with the database's mutex held: it must not call back
  /// into the database.
  std::vector<Candidate> query(const BowVector& query, double min_score, double min_common_ratio = 0.8,
                               const std::function<bool(std::uint64_t)>& skip = {}) const;
  /// query() with min_score the least score among the `reference`
  /// keyframes (ORB-SLAM2: the new keyframe's covisibles), taken from the
  /// same walk of the lists: 1 when `reference` is empty, 0 when one of
  /// them shares no word.  The same candidates as query() with that score
  /// computed beforehand by Vocabulary::score, without putting bags together.
  std::vector<Candidate> query_above(const BowVector& query, const std::vector<std::uint64_t>& reference,
                                     double min_common_ratio = 0.8,
                                     const std::function<bool(std::uint64_t)>& skip = {}) const;
  /// Keyframes (ids, ascending) listed under `word`.
  std::vector<std::uint64_t> keyframes_with(WordId word) const;
  /// The bag added for keyframe `id`, the same words and weights (empty when
  /// the keyframe is not in the database).
  BowVector bag(std::uint64_t id) const;
  /// Heap bytes of the lists and the word lists (as malloc sizes them).
  std::size_t memory_bytes() const;
  /// What the database holds: keyframes, words with a list, and postings
  /// (one per keyframe and word of its bag).
  struct Counts {
    std::size_t keyframes = 0, words = 0, postings = 0;
  };
  Counts counts() const;

 private:
  /// A word's postings in ascending ids, in one malloc'd buffer whose
  /// capacity fills its heap block (2, 4, 10, 20, 42, ... postings): 16
  /// bytes a word, where a hash-map node and a std::vector cost 80.
  class PostingList {
   public:
    PostingList() = default;
    PostingList(PostingList&& o) noexcept;
    PostingList& operator=(PostingList&& o) noexcept;
    PostingList(const PostingList&) = delete;
    PostingList& operator=(const PostingList&) = delete;
    ~PostingList();
    const Posting* begin() const { return data_; }
    const Posting* end() const { return data_ + size_; }
    bool empty() const { return size_ == 0; }
    /// The posting of keyframe `id`, or null.
    const Posting* find(std::uint32_t id) const;
    void insert(Posting p);  ///< keeps ids ascending; replaces the weight of a listed id
    void remove(std::uint32_t id);  ///< frees the buffer when the list empties
    std::size_t heap_bytes() const;

   private:
    Posting* data_ = nullptr;
    std::uint32_t size_ = 0, capacity_ = 0;
  };
  struct Tally {
    double sum = 0;  ///< DBoW2's L1 sum over the words shared with the query
    int common = 0;  ///< words shared with the query (0: not met)
  };
  static double score_of(const Tally& t) { return 0.0 - 0.5 * t.sum; }  // as Vocabulary::score
  /// Walks the lists of the query's words into tallies_ (mutex held by the
  /// caller).
  void tally(const BowVector& query) const;
  /// The candidates of the tallies, which it clears.  `skip` is asked of the
  /// keyframes met in descending shared words until one is not skipped (the
  /// largest count), then down to min_common_ratio x that count: a query
  /// meets thousands of keyframes, and only tens share that many words.
  std::vector<Candidate> select(double min_score, double min_common_ratio,
                                const std::function<bool(std::uint64_t)>& skip) const;
  /// met_ ordered by descending shared words (a counting sort), into by_common_.
  void order_by_common() const;
  /// The list of `word`, or null when none holds it (mutex held).
  const PostingList* list_of(WordId word) const;

  mutable std::mutex mutex_;
  std::vector<PostingList> inverted_;  ///< by word id: word -> keyframes
  std::size_t listed_words_ = 0;       ///< words whose list is not empty
  std::unordered_map<std::uint64_t, std::vector<WordId>> words_;  ///< keyframe id -> its words, ascending
  std::uint32_t max_id_ = 0;  ///< the largest keyframe id added
  /// One query's tallies by keyframe id (an array up to max_id_, where a
  /// hash map took most of a query's time) and the ids met, in the order
  /// met; scratch under the mutex, cleared after each query.
  mutable std::vector<Tally> tallies_;
  mutable std::vector<std::uint32_t> met_;
  mutable std::vector<std::uint32_t> by_common_;  ///< met_ by descending shared words
  mutable std::vector<std::uint32_t> common_counts_;  ///< scratch of order_by_common()
};

}  // namespace pvb::slam::place
