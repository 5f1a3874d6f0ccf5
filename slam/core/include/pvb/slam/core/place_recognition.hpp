#pragma once
// Place recognition for tracking and loop closing: the keyframes' bags of
// words in a database, and the candidate selection of ORB-SLAM2's
// KeyFrameDatabase (DetectLoopCandidates, DetectRelocalizationCandidates):
// keyframes sharing words with the query, those sharing at least 80 % of
// the most shared words and scoring at least a minimum, then scores
// accumulated over each candidate's 10 best covisibles that are candidates
// too; the best keyframe of every group whose accumulated score exceeds
// 75 % of the best group's.  docs/place_recognition.md.
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "pvb/slam/core/map.hpp"
#include "pvb/slam/place/database.hpp"
#include "pvb/slam/place/vocabulary.hpp"

namespace pvb::slam {

/// A keyframe's own neighbourhood: itself, its `covisibles` and the
/// keyframes fewer than `min_keyframe_gap` ids older.  They show its place
/// at its own (drifted) pose, so they are neither loop candidates nor
/// look-alike rivals of a loop.
std::function<bool(std::uint64_t)> own_neighbourhood(const KeyFrame& kf,
                                                     const std::vector<std::shared_ptr<KeyFrame>>& covisibles,
                                                     int min_keyframe_gap);

class PlaceRecognizer {
 public:
  /// Groups features by the node this many levels above the words (ORB-SLAM2: 4).
  static constexpr int kDirectIndexLevelsUp = 4;

  explicit PlaceRecognizer(std::shared_ptr<const place::Vocabulary> vocabulary);

  /// The bag of words and direct index of a frame's descriptors.
  void transform(const Frame& f, place::BowVector* bow, place::FeatureVector* features) const;
  /// The same, stored in the keyframe.
  void compute_bow(KeyFrame& kf) const;
  /// Adds a keyframe (its bag computed) to the database, which keeps its
  /// weights from then on: the keyframe's own bag is dropped.  Queries skip
  /// keyframes no longer in the map or bad.
  void add(KeyFrame& kf);
  /// Forgets a keyframe (culled): its postings are freed.
  void erase(std::uint64_t kf_id) { database_.erase(kf_id); }
  /// Makes room for a loaded map's keyframes (the word lists are made for
  /// the vocabulary at construction).
  void reserve(std::size_t keyframes) { database_.reserve(keyframes, 0); }
  /// A keyframe's bag: its own until add(), then the database's (the same
  /// words and weights).
  place::BowVector bag_of(const KeyFrame& kf) const;
  /// Heap bytes of the database.
  std::size_t database_bytes() const { return database_.memory_bytes(); }
  place::Database::Counts database_counts() const { return database_.counts(); }

  /// Loop candidates for `kf` (ORB-SLAM2 DetectLoopCandidates): older by at
  /// least min_keyframe_gap ids, not kf's covisibles, scoring at least the
  /// lowest score of kf against its covisibles.  Call with the map mutex held.
  std::vector<std::shared_ptr<KeyFrame>> loop_candidates(const Map& map, const KeyFrame& kf,
                                                         int min_keyframe_gap) const;
  /// Relocalisation candidates for a frame's bag (DetectRelocalizationCandidates).
  /// Call with the map mutex held.
  std::vector<std::shared_ptr<KeyFrame>> relocalisation_candidates(const Map& map,
                                                                   const place::BowVector& bow) const;
  /// The `n` best-scoring keyframes for `bow` one by one, without grouping
  /// and keeping those sharing at least half of the most shared words: the
  /// look-alike places a relocalisation is checked against.  `skip`, when
  /// given, leaves out keyframes by id before they take one of the `n` places.
  std::vector<std::shared_ptr<KeyFrame>> lookalike_candidates(
      const Map& map, const place::BowVector& bow, std::size_t n,
      const std::function<bool(std::uint64_t)>& skip = {}) const;

 private:
  std::shared_ptr<const place::Vocabulary> vocabulary_;
  place::Database database_;
};

}  // namespace pvb::slam
