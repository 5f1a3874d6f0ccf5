#include "pvb/slam/place/database.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

#include "pvb/common/memory.hpp"

namespace pvb::slam::place {
namespace {

bool by_id(const Database::Posting& p, std::uint32_t id) { return p.id < id; }

/// The capacity after `capacity` postings: the most that fill the next
/// heap block of twice the size (32, 64, 128, ... bytes with malloc's 8).
std::uint32_t grown_capacity(std::uint32_t capacity) {
  const std::size_t block = capacity == 0 ? 32 : 2 * heap_block_bytes(capacity * sizeof(Database::Posting));
  return static_cast<std::uint32_t>((block - 8) / sizeof(Database::Posting));
}

std::uint32_t checked_id(std::uint64_t id) {
  if (id > UINT32_MAX) throw std::out_of_range("keyframe database: keyframe id " + std::to_string(id) + " above 2^32 - 1");
  return static_cast<std::uint32_t>(id);
}

}  // namespace

Database::PostingList::PostingList(PostingList&& o) noexcept
    : data_(std::exchange(o.data_, nullptr)), size_(std::exchange(o.size_, 0)),
      capacity_(std::exchange(o.capacity_, 0)) {}

Database::PostingList& Database::PostingList::operator=(PostingList&& o) noexcept {
  if (this != &o) {
    std::free(data_);
    data_ = std::exchange(o.data_, nullptr);
    size_ = std::exchange(o.size_, 0);
    capacity_ = std::exchange(o.capacity_, 0);
  }
  return *this;
}

Database::PostingList::~PostingList() { std::free(data_); }

const Database::Posting* Database::PostingList::find(std::uint32_t id) const {
  const Posting* it = std::lower_bound(begin(), end(), id, by_id);
  return it != end() && it->id == id ? it : nullptr;
}

void Database::PostingList::insert(Posting p) {
  Posting* it = size_ == 0 || data_[size_ - 1].id < p.id ? data_ + size_ : std::lower_bound(data_, data_ + size_, p.id, by_id);
  if (it != data_ + size_ && it->id == p.id) {
    it->weight = p.weight;
    return;
  }
  if (size_ == capacity_) {
    const std::ptrdiff_t at = it - data_;
    const std::uint32_t capacity = grown_capacity(capacity_);
    void* grown = std::realloc(data_, capacity * sizeof(Posting));
    if (!grown) throw std::bad_alloc();
    data_ = static_cast<Posting*>(grown);
    capacity_ = capacity;
    it = data_ + at;
  }
  std::memmove(it + 1, it, static_cast<std::size_t>(data_ + size_ - it) * sizeof(Posting));
  *it = p;
  ++size_;
}

void Database::PostingList::remove(std::uint32_t id) {
  Posting* it = std::lower_bound(data_, data_ + size_, id, by_id);
  if (it == data_ + size_ || it->id != id) return;
  std::memmove(it, it + 1, static_cast<std::size_t>(data_ + size_ - it - 1) * sizeof(Posting));
  if (--size_ == 0) *this = PostingList();
}

std::size_t Database::PostingList::heap_bytes() const { return heap_block_bytes(capacity_ * sizeof(Posting)); }

const Database::PostingList* Database::list_of(WordId word) const {
  return word < inverted_.size() && !inverted_[word].empty() ? &inverted_[word] : nullptr;
}

void Database::add(std::uint64_t id, const BowVector& bow) {
  const std::uint32_t id32 = checked_id(id);
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto old = words_.find(id); old != words_.end()) {
    for (WordId word : old->second) {
      inverted_[word].remove(id32);
      if (inverted_[word].empty()) --listed_words_;
    }
  }
  std::vector<WordId> words;
  words.reserve(bow.size());
  if (!bow.empty() && bow.back().first >= inverted_.size()) inverted_.resize(bow.back().first + std::size_t{1});
  for (const auto& [word, w] : bow) {
    if (inverted_[word].empty()) ++listed_words_;
    inverted_[word].insert({id32, w});
    words.push_back(word);
  }
  words_[id] = std::move(words);
  max_id_ = std::max(max_id_, id32);
}

void Database::reserve(std::size_t keyframes, std::size_t words) {
  std::lock_guard<std::mutex> lock(mutex_);
  words_.reserve(keyframes);
  if (words > inverted_.size()) inverted_.resize(words);
}

void Database::erase(std::uint64_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = words_.find(id);
  if (it == words_.end()) return;
  for (WordId word : it->second) {
    inverted_[word].remove(static_cast<std::uint32_t>(id));
    if (inverted_[word].empty()) --listed_words_;
  }
  words_.erase(it);
}

std::size_t Database::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return words_.size();
}

BowVector Database::bag(std::uint64_t id) const {
  std::lock_guard<std::mutex> lock(mutex_);
  BowVector bow;
  const auto it = words_.find(id);
  if (it == words_.end()) return bow;
  bow.reserve(it->second.size());
  for (WordId word : it->second) {  // present: add() listed it under every one of its words
    const double weight = inverted_[word].find(static_cast<std::uint32_t>(id))->weight;  // a copy: packed
    bow.emplace_back(word, weight);
  }
  return bow;
}

std::size_t Database::memory_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t bytes = vector_heap_bytes(inverted_) + unordered_map_bytes(words_) + vector_heap_bytes(tallies_) +
                      vector_heap_bytes(met_);
  for (const PostingList& list : inverted_) bytes += list.heap_bytes();
  for (const auto& [id, words] : words_) bytes += vector_heap_bytes(words);
  return bytes;
}

Database::Counts Database::counts() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Counts c;
  c.keyframes = words_.size();
  c.words = listed_words_;
  for (const auto& [id, words] : words_) c.postings += words.size();
  return c;
}

std::vector<Candidate> Database::query(const BowVector& query, double min_score, double min_common_ratio,
                                       const std::function<bool(std::uint64_t)>& skip) const {
  std::lock_guard<std::mutex> lock(mutex_);
  tally(query);
  return select(min_score, min_common_ratio, skip);
}

std::vector<Candidate> Database::query_above(const BowVector& query, const std::vector<std::uint64_t>& reference,
                                             double min_common_ratio,
                                             const std::function<bool(std::uint64_t)>& skip) const {
  std::lock_guard<std::mutex> lock(mutex_);
  tally(query);
  double min_score = 1.0;
  for (std::uint64_t id : reference) {
    const bool met = id < tallies_.size() && tallies_[id].common > 0;
    min_score = std::min(min_score, met ? score_of(tallies_[id]) : 0.0);
  }
  return select(min_score, min_common_ratio, skip);
}

void Database::tally(const BowVector& query) const {
  // The sum runs over the query's words in ascending order, as
  // Vocabulary::score merges two bags, so the scores are the same doubles.
  for (std::uint32_t id : met_) tallies_[id] = Tally{};  // left by a query a skip() threw out of
  met_.clear();
  if (tallies_.size() <= max_id_ && !words_.empty()) tallies_.resize(std::size_t{max_id_} + 1);
  for (const auto& [word, x] : query) {
    const PostingList* list = list_of(word);
    if (!list) continue;
    for (const Posting& p : *list) {
      Tally& t = tallies_[p.id];
      if (t.common++ == 0) met_.push_back(p.id);
      t.sum += std::fabs(x - p.weight) - std::fabs(x) - std::fabs(p.weight);
    }
  }
}

void Database::order_by_common() const {
  int top = 0;
  for (std::uint32_t id : met_) top = std::max(top, tallies_[id].common);
  // Bucket starts from the top count down; ids keep the order met within a count.
  common_counts_.assign(static_cast<std::size_t>(top) + 2, 0);
  for (std::uint32_t id : met_) ++common_counts_[static_cast<std::size_t>(top - tallies_[id].common) + 1];
  for (std::size_t c = 1; c < common_counts_.size(); ++c) common_counts_[c] += common_counts_[c - 1];
  by_common_.resize(met_.size());
  for (std::uint32_t id : met_) by_common_[common_counts_[static_cast<std::size_t>(top - tallies_[id].common)]++] = id;
}

std::vector<Candidate> Database::select(double min_score, double min_common_ratio,
                                        const std::function<bool(std::uint64_t)>& skip) const {
  order_by_common();
  std::vector<Candidate> out;
  int max_common = 0;  // the largest count among the keyframes not skipped
  for (std::uint32_t id : by_common_) {
    const Tally& t = tallies_[id];
    if (max_common > 0 && t.common < min_common_ratio * max_common) break;
    if (skip && skip(id)) continue;
    if (max_common == 0) max_common = t.common;
    const double s = score_of(t);
    if (s >= min_score) out.push_back({id, t.common, s});
  }
  for (std::uint32_t id : met_) tallies_[id] = Tally{};
  met_.clear();
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score > b.score : a.id < b.id;
  });
  return out;
}

std::vector<std::uint64_t> Database::keyframes_with(WordId word) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::uint64_t> ids;
  if (const PostingList* list = list_of(word))
    for (const Posting& p : *list) ids.push_back(p.id);
  return ids;
}

}  // namespace pvb::slam::place
