#include "pvb/slam/place/database.hpp"

#include <algorithm>

namespace pvb::slam::place {
namespace {

/// Removes `id` from an ascending list (no-op when absent).
void remove_sorted(std::vector<std::uint64_t>& ids, std::uint64_t id) {
  const auto it = std::lower_bound(ids.begin(), ids.end(), id);
  if (it != ids.end() && *it == id) ids.erase(it);
}

/// Inserts `id` into an ascending list; keyframes come with growing ids, so
/// this is mostly an append.
void insert_sorted(std::vector<std::uint64_t>& ids, std::uint64_t id) {
  if (ids.empty() || ids.back() < id) {
    ids.push_back(id);
    return;
  }
  const auto it = std::lower_bound(ids.begin(), ids.end(), id);
  if (it == ids.end() || *it != id) ids.insert(it, id);
}

}  // namespace

void Database::add(std::uint64_t id, const BowVector& bow) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (const auto old = bows_.find(id); old != bows_.end()) {
    for (const auto& [word, w] : old->second) {
      auto& ids = inverted_[word];
      remove_sorted(ids, id);
      if (ids.empty()) inverted_.erase(word);
    }
  }
  for (const auto& [word, w] : bow) insert_sorted(inverted_[word], id);
  bows_[id] = bow;
}

void Database::erase(std::uint64_t id) {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = bows_.find(id);
  if (it == bows_.end()) return;
  for (const auto& [word, w] : it->second) {
    const auto list = inverted_.find(word);
    if (list == inverted_.end()) continue;
    remove_sorted(list->second, id);
    if (list->second.empty()) inverted_.erase(list);
  }
  bows_.erase(it);
}

std::size_t Database::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return bows_.size();
}

std::vector<Candidate> Database::query(const BowVector& query, double min_score, double min_common_ratio,
                                       const std::function<bool(std::uint64_t)>& skip) const {
  std::lock_guard<std::mutex> lock(mutex_);
  // Words in common per keyframe; -1 marks a skipped one, so that skip() is
  // asked once per keyframe.
  std::unordered_map<std::uint64_t, int> common;
  for (const auto& [word, w] : query) {
    const auto list = inverted_.find(word);
    if (list == inverted_.end()) continue;
    for (const std::uint64_t id : list->second) {
      auto [it, inserted] = common.try_emplace(id, 0);
      if (inserted && skip && skip(id)) it->second = -1;
      if (it->second >= 0) ++it->second;
    }
  }
  int max_common = 0;
  for (const auto& [id, n] : common) max_common = std::max(max_common, n);
  std::vector<Candidate> out;
  if (max_common == 0) return out;
  const double min_common = min_common_ratio * max_common;
  for (const auto& [id, n] : common) {
    if (n <= 0 || n < min_common) continue;
    const double s = Vocabulary::score(query, bows_.at(id));
    if (s >= min_score) out.push_back({id, n, s});
  }
  std::sort(out.begin(), out.end(), [](const Candidate& a, const Candidate& b) {
    return a.score != b.score ? a.score > b.score : a.id < b.id;
  });
  return out;
}

std::vector<std::uint64_t> Database::keyframes_with(WordId word) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = inverted_.find(word);
  return it == inverted_.end() ? std::vector<std::uint64_t>{} : it->second;
}

}  // namespace pvb::slam::place
