#pragma once
// Ground-truth labels for place recognition: every accepted loop and every
// relocalisation is judged true or false by comparing the relative pose the
// SLAM system estimated between the two views with the true one, and the
// true revisits (keyframes that came back to where an earlier keyframe
// looked from) are found so that missed loops can be counted.
// docs/place_recognition.md, "Ground-truth labels".
#include <cstdint>
#include <string>
#include <vector>

#include "pvb/eval/trajectory.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::eval {

/// A loop or a relocalisation as the SLAM system reports it.
struct PlaceEvent {
  std::int64_t t_ns = 0;      ///< the query view (new keyframe, relocalised frame)
  std::int64_t ref_t_ns = 0;  ///< the keyframe it matched
  geom::SE3d T_q_r;           ///< estimated pose of the query camera relative to the matched one (p_q = T_q_r p_r)
};

struct PlaceLabelOptions {
  /// A match is true when its relative pose is within these of the truth.
  /// The look-alikes of a PV station are a panel (~1 m), a table or a row
  /// pitch (metres) or a brick (0.2 m) away; a true loop's verified pose
  /// is off by the map's local error (millimetres to a few centimetres).
  double max_translation_m = 0.10;
  double max_rotation_deg = 5.0;
  /// A keyframe is a true revisit when an earlier keyframe, at least
  /// min_gap_s older, had its camera within revisit_radius_m and its
  /// optical axis within revisit_angle_deg.
  double revisit_radius_m = 1.0;
  double revisit_angle_deg = 30.0;
  double revisit_min_gap_s = 20.0;
  /// A true relocalisation closes the revisit episode that starts within
  /// this long after it, or at the first keyframe after it however late
  /// (tracking goes on in the old map from there, and made no keyframe
  /// elsewhere in between).
  double relocalisation_lead_s = 5.0;
  double max_dt_s = 0.02;  ///< ground truth is looked up this close in time
};

/// One event with its label.
struct LabelledPlaceEvent {
  PlaceEvent event;
  bool judged = false;  ///< ground truth found for both views
  bool correct = false; ///< judged and within the tolerance
  double error_m = 0, error_deg = 0;  ///< of the relative pose
};

/// A run of consecutive revisiting keyframes.
struct RevisitEpisode {
  std::int64_t first_t_ns = 0, last_t_ns = 0;
  int keyframes = 0;
  bool closed = false;  ///< a true loop inside it, or a true relocalisation inside it or just before it
};

struct PlaceLabels {
  std::vector<LabelledPlaceEvent> loops, relocalisations;
  std::vector<RevisitEpisode> revisits;
  int loops_true = 0, loops_false = 0, loops_missed = 0;
  int relocalisations_true = 0, relocalisations_false = 0;
  int unjudged = 0;  ///< events without ground truth at one of their times
};

/// Judges one event against ground truth (`gt` poses T_w_c).
LabelledPlaceEvent label_place_event(const Trajectory& gt, const PlaceEvent& e, const PlaceLabelOptions& options);

/// The true revisit episodes among keyframes at `keyframe_t_ns` (ascending).
std::vector<RevisitEpisode> find_revisits(const Trajectory& gt, const std::vector<std::int64_t>& keyframe_t_ns,
                                          const PlaceLabelOptions& options);

/// Labels every loop and relocalisation, finds the revisits and counts the
/// missed ones (episodes that no true loop or relocalisation closed).
PlaceLabels label_place_events(const Trajectory& gt, const std::vector<PlaceEvent>& loops,
                               const std::vector<PlaceEvent>& relocalisations,
                               const std::vector<std::int64_t>& keyframe_t_ns, const PlaceLabelOptions& options);

/// The labels as one JSON object (metrics.json's "place_recognition" minus
/// the detector's own counts): {"loops_true", "loops_false", "loops_missed",
/// "revisits", "relocalisations_true", "relocalisations_false", "unjudged",
/// "max_translation_m", "max_rotation_deg", "loop_events": [...],
/// "relocalisation_events": [...]}; events carry t_s, ref_t_s, correct,
/// error_m, error_deg.
std::string to_json(const PlaceLabels& labels, const PlaceLabelOptions& options);

}  // namespace pvb::eval
