#include "pvb/eval/localisation.hpp"

#include <algorithm>
#include <cmath>

#include "pvb/common/text.hpp"

namespace pvb::eval {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  const double hi = v[n / 2];
  if (n % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + n / 2));
}

/// The estimate nearest in time to t_ns within max_dt_ns, or null.
const geom::StampedPose* at_time(const Trajectory& est, std::int64_t t_ns, std::int64_t max_dt_ns) {
  const auto it = std::lower_bound(est.poses.begin(), est.poses.end(), t_ns,
                                   [](const geom::StampedPose& p, std::int64_t t) { return p.t_ns < t; });
  const geom::StampedPose* best = nullptr;
  for (auto c : {it, it == est.poses.begin() ? it : it - 1}) {
    if (c == est.poses.end()) continue;
    if (std::llabs(c->t_ns - t_ns) <= max_dt_ns && (!best || std::llabs(c->t_ns - t_ns) < std::llabs(best->t_ns - t_ns)))
      best = &*c;
  }
  return best;
}

}  // namespace

const std::vector<PrecisionClass>& precision_classes() {
  static const std::vector<PrecisionClass> classes = {
      {"fine", 0.05, 1.0}, {"high", 0.25, 2.0}, {"medium", 0.5, 5.0}, {"coarse", 5.0, 10.0}};
  return classes;
}

LocalisationScores score_localisation(const Trajectory& gt_world, const Trajectory& est_map,
                                      const geom::SE3d& T_world_map, const LocalisationOptions& o) {
  LocalisationScores s;
  const std::vector<PrecisionClass>& classes = precision_classes();
  std::vector<std::size_t> within(classes.size(), 0);
  std::vector<double> t_err, r_err;
  const geom::SE3d T_map_world = T_world_map.inverse();
  double driven = 0;
  s.frames = gt_world.size();
  for (std::size_t i = 0; i < gt_world.size(); ++i) {
    if (i > 0) driven += (gt_world.poses[i].T_w_c.translation() - gt_world.poses[i - 1].T_w_c.translation()).norm();
    const geom::StampedPose* e = at_time(est_map, gt_world.poses[i].t_ns, o.max_dt_ns);
    if (!e) {
      s.translation_error_m.push_back(-1);
      s.rotation_error_deg.push_back(-1);
      continue;
    }
    const geom::SE3d T_map_c_gt = T_map_world * gt_world.poses[i].T_w_c;
    const geom::SE3d d = T_map_c_gt.inverse() * e->T_w_c;
    const double dt = d.translation().norm(), dr = geom::rotation_angle_rad(d.linear()) * 180.0 / M_PI;
    s.translation_error_m.push_back(dt);
    s.rotation_error_deg.push_back(dr);
    t_err.push_back(dt);
    r_err.push_back(dr);
    if (!s.first_pose_frame) {
      s.first_pose_frame = i;
      s.metres_to_first_pose = driven;
    }
    for (std::size_t k = 0; k < classes.size(); ++k)
      within[k] += dt <= classes[k].max_translation_m && dr <= classes[k].max_rotation_deg ? 1 : 0;
    s.wrong_place += dt > o.wrong_place_m || dr > o.wrong_place_deg ? 1 : 0;
  }
  s.posed = t_err.size();
  for (std::size_t k = 0; k < classes.size(); ++k)
    s.share_within.push_back(s.frames ? static_cast<double>(within[k]) / static_cast<double>(s.frames) : 0.0);
  s.translation_median_m = median(t_err);
  s.rotation_median_deg = median(r_err);
  s.translation_max_m = t_err.empty() ? 0.0 : *std::max_element(t_err.begin(), t_err.end());
  return s;
}

std::string localisation_json(const LocalisationScores& s) {
  std::string within = "{";
  const std::vector<PrecisionClass>& classes = precision_classes();
  for (std::size_t k = 0; k < classes.size() && k < s.share_within.size(); ++k)
    within += (k ? ", \"" : "\"") + classes[k].name + "\": {\"max_translation_m\": " +
              json_number(classes[k].max_translation_m, 6) + ", \"max_rotation_deg\": " +
              json_number(classes[k].max_rotation_deg, 6) + ", \"share\": " + json_number(s.share_within[k], 6) + "}";
  within += "}";
  const bool any = s.posed > 0;
  return "{\"frames\": " + std::to_string(s.frames) + ", \"posed\": " + std::to_string(s.posed) +
         ", \"within\": " + within + ", \"wrong_place\": " + std::to_string(s.wrong_place) +
         ", \"first_pose_frame\": " + (s.first_pose_frame ? std::to_string(*s.first_pose_frame) : "null") +
         ", \"metres_to_first_pose\": " + (s.first_pose_frame ? json_number(s.metres_to_first_pose, 6) : "null") +
         ", \"translation_median_m\": " + (any ? json_number(s.translation_median_m, 6) : "null") +
         ", \"rotation_median_deg\": " + (any ? json_number(s.rotation_median_deg, 6) : "null") +
         ", \"translation_max_m\": " + (any ? json_number(s.translation_max_m, 6) : "null") + "}";
}

}  // namespace pvb::eval
