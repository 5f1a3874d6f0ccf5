#include "pvb/slam/core/patch_refine.hpp"

namespace pvb::slam {

bool align_to_reference(Frame& f, std::size_t i, const MapPoint& mp, const PatchAlignParams& params) {
  if (!f.pyramid) return false;
  f.aligned_for[i] = mp.id();
  const auto ref = mp.reference_keyframe();
  if (!ref || ref->bad() || !ref->frame().pyramid || ref->frame_id() == f.id) return false;
  const long idx = mp.index_in(ref->id());
  if (idx < 0) return false;
  const Frame& rf = ref->frame();
  const auto j = static_cast<std::size_t>(idx);
  const CameraModel& cam = *f.cam;
  // The reference keypoint's ray at the point's depth there, and the affine
  // map of a fronto-parallel patch around it into f.
  const double z_ref = (rf.T_c_w * mp.p_w()).z();
  if (!(z_ref > 0)) return false;
  const geom::SE3d T_cur_ref = f.T_c_w * rf.T_c_w.inverse();
  const Eigen::Vector2d u_ref(rf.keys_un[j].pt.x, rf.keys_un[j].pt.y);
  if (!((T_cur_ref * cam.unproject(u_ref, z_ref)).z() > 0)) return false;
  const auto to_cur = [&](double du, double dv) {
    return cam.project(T_cur_ref * cam.unproject(u_ref + Eigen::Vector2d(du, dv), z_ref));
  };
  Eigen::Matrix2d A;
  A.col(0) = 0.5 * (to_cur(1, 0) - to_cur(-1, 0));
  A.col(1) = 0.5 * (to_cur(0, 1) - to_cur(0, -1));
  const cv::Point2f& key = f.keys[i];
  Eigen::Vector2d aligned;
  if (!align_patch(*rf.pyramid, Eigen::Vector2d(rf.keys[j].x, rf.keys[j].y), A, *f.pyramid, f.keys_un[i].octave,
                   Eigen::Vector2d(key.x, key.y), params, &aligned))
    return false;
  f.move_keypoint(i, aligned);
  return true;
}

std::pair<int, int> align_keyframe_observations(KeyFrame& kf, const PatchAlignParams& params) {
  Frame& f = kf.frame_for_alignment();
  if (!f.pyramid) return {0, 0};
  int tried = 0, aligned = 0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    const auto& mp = f.map_points[i];
    if (!mp || mp->bad() || f.aligned_for[i] == mp->id()) continue;
    ++tried;
    aligned += align_to_reference(f, i, *mp, params) ? 1 : 0;
  }
  return {tried, aligned};
}

}  // namespace pvb::slam
