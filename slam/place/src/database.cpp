#include "pvb/slam/place/database.hpp"

#include <algorithm>
#include <cmath>

#include "pvb/common/memory.hpp"

namespace pvb::slam::place {
namespace {

bool by_id(const Database::Posting& p, std::uint64_t id) { return p.id < id; }

/// Removes `id` from a list in ascending ids (no-op when absent).
void remove_sorted(std::vector<Database::Posting>& list, std::uint64_t id) {
  const auto it = std::lower_bound(list.begin(), list.end(), id, by_id);
  if (it != list.end() && it->id == id) list.erase(it);
}

/// Inserts a posting into a list in ascending ids; keyframes come with
/// growing ids, so this is mostly an append.
void insert_sorted(std::vector<Database::Posting>& list, Database::Posting p) {
  if (list.empty() || list.back().id < p.id) {
    list.push_back(p);
    return;
  }
  const auto it = std::lower_bound(list.begin(), list.end(), p.id, by_id);
  if (it == list.end() || it->id != p.id) list.insert(it, p);
}

}  // namespace

void Database::add(std::uint64_t id, const BowVector& bow) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto old = words_.find(id); old != words_.end()) {
    for (WordId word : old->second) {
      auto& ids = inverted_[word];
      remove_sorted(ids, id);
      if (ids.empty()) inverted_.erase(word);
    }
  }
  std::vector<WordId> words;
  words.reserve(bow.size());
  for (const auto& [word, w] : bow) {
    insert_sorted(inverted_[word], {id, w});
    words.push_back(word);
  }
  words_[id] = std::move(words);
}

void Database::reserve(std::size_t keyframes, std::size_t words) {
  std::lock_guard<std::mutex> lock(mutex_);
  words_.reserve(keyframes);
  inverted_.reserve(words);
}

void Database::erase(std::uint64_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = words_.find(id);
  if (it == words_.end()) return;
  for (WordId word : it->second) {
    const auto list = inverted_.find(word);
    if (list == inverted_.end()) continue;
    remove_sorted(list->second, id);
    if (list->second.empty()) inverted_.erase(list);
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
  for (WordId word : it->second) {
    const std::vector<Posting>& list = inverted_.at(word);
    const auto p = std::lower_bound(list.begin(), list.end(), id, by_id);
    bow.emplace_back(word, p->weight);  // present: add() listed it under every one of its words
  }
  return bow;
}

std::size_t Database::memory_bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t bytes = unordered_map_bytes(inverted_) + unordered_map_bytes(words_);
  for (const auto& [word, list] : inverted_) bytes += vector_heap_bytes(list);
  for (const auto& [id, words] : words_) bytes += vector_heap_bytes(words);
  return bytes;
}

std::vector<Candidate> Database::query(const BowVector& query, double min_score, double min_common_ratio,
                                       const std::function<bool(std::uint64_t)>& skip) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return select(tally(query, skip), min_score, min_common_ratio);
}

std::vector<Candidate> Database::query_above(const BowVector& query, const std::vector<std::uint64_t>& reference,
                                             double min_common_ratio,
                                             const std::function<bool(std::uint64_t)>& skip) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const std::unordered_map<std::uint64_t, Tally> t = tally(query, skip);
  double min_score = 1.0;
  for (std::uint64_t id : reference) {
    const auto it = t.find(id);
    min_score = std::min(min_score, it == t.end() ? 0.0 : score_of(it->second));
  }
  return select(t, min_score, min_common_ratio);
}

std::unordered_map<std::uint64_t, Database::Tally> Database::tally(
    const BowVector& query, const std::function<bool(std::uint64_t)>& skip) const {
  // The sum runs over the query's words in ascending order, as
  // Vocabulary::score merges two bags, so the scores are the same doubles.
  std::unordered_map<std::uint64_t, Tally> tally;
  for (const auto& [word, x] : query) {
    const auto list = inverted_.find(word);
    if (list == inverted_.end()) continue;
    for (const Posting& p : list->second) {
      auto [it, inserted] = tally.try_emplace(p.id);
      if (inserted && skip) it->second.skipped = skip(p.id);
      ++it->second.common;
      it->second.sum += std::fabs(x - p.weight) - std::fabs(x) - std::fabs(p.weight);
    }
  }
  return tally;
}

std::vector<Candidate> Database::select(const std::unordered_map<std::uint64_t, Tally>& tally, double min_score,
                                        double min_common_ratio) {
  int max_common = 0;
  for (const auto& [id, t] : tally)
    if (!t.skipped) max_common = std::max(max_common, t.common);
  std::vector<Candidate> out;
  if (max_common == 0) return out;
  const double min_common = min_common_ratio * max_common;
  for (const auto& [id, t] : tally) {
    if (t.skipped || t.common < min_common) continue;
    const double s = score_of(t);
    if (s >= min_score) out.push_back({id, t.common, s});
  }
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score > b.score : a.id < b.id;
  });
  return out;
}

std::vector<std::uint64_t> Database::keyframes_with(WordId word) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::uint64_t> ids;
  if (const auto it = inverted_.find(word); it != inverted_.end())
    for (const Posting& p : it->second) ids.push_back(p.id);
  return ids;
}

}  // namespace pvb::slam::place
