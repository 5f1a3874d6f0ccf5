#include "pvb/slam/core/place_recognition.hpp"

#include <algorithm>
#include <map>
#include <set>

namespace pvb::slam {
namespace {

using KeyFramePtr = std::shared_ptr<KeyFrame>;

/// ORB-SLAM2's accumulation of candidate scores over covisibility groups:
/// each candidate's score plus those of its 10 best covisibles that are
/// candidates too; the best-scoring keyframe of every group whose sum is
/// above 75 % of the best sum, each keyframe once, best group first.
std::vector<KeyFramePtr> accumulate_groups(const Map& map, const std::vector<place::Candidate>& found) {
  std::map<std::uint64_t, double> score;
  for (const auto& c : found) score[c.id] = c.score;
  struct Group {
    double acc;
    KeyFramePtr best;
  };
  std::vector<Group> groups;
  double best_acc = 0;
  for (const auto& c : found) {
    auto it = map.keyframes().find(c.id);
    if (it == map.keyframes().end() || it->second->bad()) continue;
    Group g{c.score, it->second};
    double best_score = c.score;
    for (const auto& n : it->second->best_covisibles(10)) {
      auto s = score.find(n->id());
      if (s == score.end() || n->bad()) continue;
      g.acc += s->second;
      if (s->second > best_score) {
        best_score = s->second;
        g.best = n;
      }
    }
    best_acc = std::max(best_acc, g.acc);
    groups.push_back(g);
  }
  std::stable_sort(groups.begin(), groups.end(), [](const Group& a, const Group& b) { return a.acc > b.acc; });
  std::vector<KeyFramePtr> out;
  std::set<std::uint64_t> taken;
  for (const Group& g : groups)
    if (g.acc > 0.75 * best_acc && taken.insert(g.best->id()).second) out.push_back(g.best);
  return out;
}

}  // namespace

PlaceRecognizer::PlaceRecognizer(std::shared_ptr<const place::Vocabulary> vocabulary)
    : vocabulary_(std::move(vocabulary)) {
  if (vocabulary_) database_.reserve(0, vocabulary_->size());  // one list head per word, once
}

void PlaceRecognizer::transform(const Frame& f, place::BowVector* bow, place::FeatureVector* features) const {
  vocabulary_->transform(f.descriptors, bow, features, kDirectIndexLevelsUp);
}

void PlaceRecognizer::compute_bow(KeyFrame& kf) const {
  place::BowVector bow;
  place::FeatureVector features;
  transform(kf.frame(), &bow, &features);
  kf.set_bow(std::move(bow), std::move(features));
}

void PlaceRecognizer::add(KeyFrame& kf) {
  database_.add(kf.id(), kf.bow());
  kf.drop_bow();
}

place::BowVector PlaceRecognizer::bag_of(const KeyFrame& kf) const {
  return kf.bow().empty() ? database_.bag(kf.id()) : kf.bow();
}

std::function<bool(std::uint64_t)> own_neighbourhood(const KeyFrame& kf, const std::vector<KeyFramePtr>& covisibles,
                                                     int min_keyframe_gap) {
  auto connected = std::make_shared<std::set<std::uint64_t>>();
  connected->insert(kf.id());
  for (const auto& n : covisibles) connected->insert(n->id());
  const std::uint64_t newest = kf.id();
  const auto gap = static_cast<std::uint64_t>(min_keyframe_gap);
  return [connected, newest, gap](std::uint64_t id) { return connected->count(id) > 0 || id + gap > newest; };
}

std::vector<KeyFramePtr> PlaceRecognizer::loop_candidates(const Map& map, const KeyFrame& kf,
                                                          int min_keyframe_gap) const {
  // ORB-SLAM2: the least score of the covisibles is the threshold (0 for a
  // keyframe without any); the database computes it in the same walk.
  const std::vector<KeyFramePtr> covisibles = kf.best_covisibles(-1);
  std::vector<std::uint64_t> reference;
  for (const auto& n : covisibles)
    if (!n->bad()) reference.push_back(n->id());
  const auto own = own_neighbourhood(kf, covisibles, min_keyframe_gap);
  const auto skip = [&](std::uint64_t id) {
    if (own(id)) return true;
    auto it = map.keyframes().find(id);
    return it == map.keyframes().end() || it->second->bad();
  };
  if (covisibles.empty()) return accumulate_groups(map, database_.query(kf.bow(), 0.0, 0.8, skip));
  return accumulate_groups(map, database_.query_above(kf.bow(), reference, 0.8, skip));
}

std::vector<KeyFramePtr> PlaceRecognizer::relocalisation_candidates(const Map& map,
                                                                    const place::BowVector& bow) const {
  const auto skip = [&](std::uint64_t id) {
    auto it = map.keyframes().find(id);
    return it == map.keyframes().end() || it->second->bad();
  };
  return accumulate_groups(map, database_.query(bow, 0.0, 0.8, skip));
}

std::vector<KeyFramePtr> PlaceRecognizer::lookalike_candidates(
    const Map& map, const place::BowVector& bow, std::size_t n,
    const std::function<bool(std::uint64_t)>& also_skip) const {
  const auto skip = [&](std::uint64_t id) {
    if (also_skip && also_skip(id)) return true;
    auto it = map.keyframes().find(id);
    return it == map.keyframes().end() || it->second->bad();
  };
  std::vector<KeyFramePtr> out;
  for (const place::Candidate& c : database_.query(bow, 0.0, 0.5, skip)) {
    if (out.size() == n) break;
    out.push_back(map.keyframes().at(c.id));
  }
  return out;
}

}  // namespace pvb::slam
