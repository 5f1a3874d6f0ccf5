#include "pvb/eval/place_labels.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>

#include "pvb/common/text.hpp"
#include "pvb/geometry/angles.hpp"

namespace pvb::eval {
namespace {

using geom::kRadToDeg;

/// The ground-truth pose nearest in time to t_ns, when within max_dt_s.
std::optional<geom::SE3d> gt_at(const Trajectory& gt, std::int64_t t_ns, double max_dt_s) {
  if (gt.empty()) return std::nullopt;
  auto it = std::lower_bound(gt.poses.begin(), gt.poses.end(), t_ns,
                             [](const geom::StampedPose& p, std::int64_t t) { return p.t_ns < t; });
  const geom::StampedPose* best = nullptr;
  if (it != gt.poses.end()) best = &*it;
  if (it != gt.poses.begin()) {
    const auto& prev = *std::prev(it);
    if (!best || std::llabs(prev.t_ns - t_ns) <= std::llabs(best->t_ns - t_ns)) best = &prev;
  }
  if (static_cast<double>(std::llabs(best->t_ns - t_ns)) * 1e-9 > max_dt_s) return std::nullopt;
  return best->T_w_c;
}

Eigen::Vector3d optical_axis_w(const geom::SE3d& T_w_c) { return T_w_c.linear().col(2); }

}  // namespace

LabelledPlaceEvent label_place_event(const Trajectory& gt, const PlaceEvent& e, const PlaceLabelOptions& options) {
  LabelledPlaceEvent out;
  out.event = e;
  const auto T_w_q = gt_at(gt, e.t_ns, options.max_dt_s);
  const auto T_w_r = gt_at(gt, e.ref_t_ns, options.max_dt_s);
  if (!T_w_q || !T_w_r) return out;
  const geom::SE3d T_q_r_gt = T_w_q->inverse() * *T_w_r;
  const geom::SE3d err = e.T_q_r.inverse() * T_q_r_gt;
  out.judged = true;
  out.error_m = err.translation().norm();
  out.error_deg = geom::rotation_angle_rad(err.linear()) * kRadToDeg;
  out.correct = out.error_m <= options.max_translation_m && out.error_deg <= options.max_rotation_deg;
  return out;
}

std::vector<RevisitEpisode> find_revisits(const Trajectory& gt, const std::vector<std::int64_t>& keyframe_t_ns,
                                          const PlaceLabelOptions& options) {
  struct Known {
    std::int64_t t_ns;
    geom::SE3d T_w_c;
  };
  std::vector<Known> kfs;
  for (std::int64_t t : keyframe_t_ns)
    if (auto T = gt_at(gt, t, options.max_dt_s)) kfs.push_back({t, *T});
  const double min_cos = std::cos(options.revisit_angle_deg / kRadToDeg);
  const auto gap_ns = static_cast<std::int64_t>(options.revisit_min_gap_s * 1e9);
  std::vector<RevisitEpisode> episodes;
  bool in_episode = false;
  for (std::size_t i = 0; i < kfs.size(); ++i) {
    bool revisit = false;
    for (std::size_t j = 0; j < i && !revisit; ++j) {
      if (kfs[i].t_ns - kfs[j].t_ns < gap_ns) break;  // ascending: the rest are newer
      revisit = (kfs[i].T_w_c.translation() - kfs[j].T_w_c.translation()).norm() <= options.revisit_radius_m &&
                optical_axis_w(kfs[i].T_w_c).dot(optical_axis_w(kfs[j].T_w_c)) >= min_cos;
    }
    if (revisit && in_episode) {
      episodes.back().last_t_ns = kfs[i].t_ns;
      ++episodes.back().keyframes;
    } else if (revisit) {
      episodes.push_back({kfs[i].t_ns, kfs[i].t_ns, 1, false});
    }
    in_episode = revisit;
  }
  return episodes;
}

PlaceLabels label_place_events(const Trajectory& gt, const std::vector<PlaceEvent>& loops,
                               const std::vector<PlaceEvent>& relocalisations,
                               const std::vector<std::int64_t>& keyframe_t_ns, const PlaceLabelOptions& options) {
  PlaceLabels out;
  const auto judge = [&](const std::vector<PlaceEvent>& events, std::vector<LabelledPlaceEvent>* labelled,
                         int* n_true, int* n_false) {
    for (const PlaceEvent& e : events) {
      labelled->push_back(label_place_event(gt, e, options));
      const auto& l = labelled->back();
      if (!l.judged) ++out.unjudged;
      else if (l.correct) ++*n_true;
      else ++*n_false;
    }
  };
  judge(loops, &out.loops, &out.loops_true, &out.loops_false);
  judge(relocalisations, &out.relocalisations, &out.relocalisations_true, &out.relocalisations_false);
  out.revisits = find_revisits(gt, keyframe_t_ns, options);
  const auto lead_ns = static_cast<std::int64_t>(options.relocalisation_lead_s * 1e9);
  for (RevisitEpisode& ep : out.revisits) {
    // A loop closes the episode it is found in; a relocalisation also the
    // one it leads into: the keyframes after it are made on the old map.
    const auto inside = [&](const LabelledPlaceEvent& l, std::int64_t lead) {
      return l.correct && l.event.t_ns >= ep.first_t_ns - lead && l.event.t_ns <= ep.last_t_ns;
    };
    const auto leads_into = [&](const LabelledPlaceEvent& l) {
      if (inside(l, lead_ns)) return true;
      const auto next = std::upper_bound(keyframe_t_ns.begin(), keyframe_t_ns.end(), l.event.t_ns);
      return l.correct && next != keyframe_t_ns.end() && *next == ep.first_t_ns;
    };
    ep.closed = std::any_of(out.loops.begin(), out.loops.end(), [&](const auto& l) { return inside(l, 0); }) ||
                std::any_of(out.relocalisations.begin(), out.relocalisations.end(), leads_into);
    if (!ep.closed) ++out.loops_missed;
  }
  return out;
}

namespace {

std::string events_json(const std::vector<LabelledPlaceEvent>& events) {
  std::string out = "[";
  for (std::size_t i = 0; i < events.size(); ++i) {
    const auto& l = events[i];
    out += std::string(i ? ", " : "") + "{\"t_s\": " + json_number(l.event.t_ns * 1e-9, 12) +
           ", \"ref_t_s\": " + json_number(l.event.ref_t_ns * 1e-9, 12) +
           ", \"judged\": " + (l.judged ? "true" : "false") + ", \"correct\": " + (l.correct ? "true" : "false") +
           ", \"error_m\": " + json_number(l.error_m, 6) + ", \"error_deg\": " + json_number(l.error_deg, 6) + "}";
  }
  return out + "]";
}

}  // namespace

std::string to_json(const PlaceLabels& labels, const PlaceLabelOptions& options) {
  return "{\"loops_true\": " + std::to_string(labels.loops_true) +
         ", \"loops_false\": " + std::to_string(labels.loops_false) +
         ", \"loops_missed\": " + std::to_string(labels.loops_missed) +
         ", \"revisits\": " + std::to_string(labels.revisits.size()) +
         ", \"relocalisations_true\": " + std::to_string(labels.relocalisations_true) +
         ", \"relocalisations_false\": " + std::to_string(labels.relocalisations_false) +
         ", \"unjudged\": " + std::to_string(labels.unjudged) +
         ", \"max_translation_m\": " + json_number(options.max_translation_m, 6) +
         ", \"max_rotation_deg\": " + json_number(options.max_rotation_deg, 6) +
         ", \"loop_events\": " + events_json(labels.loops) +
         ", \"relocalisation_events\": " + events_json(labels.relocalisations) + "}";
}

}  // namespace pvb::eval
