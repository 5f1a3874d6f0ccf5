#include "pvb/slam/core/frame_pose.hpp"

#include <algorithm>

namespace pvb::slam {

int optimize_frame_pose(Frame& f) {
  std::vector<Eigen::Vector3d> pts;
  std::vector<Observation> obs;
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (!f.map_points[i]) continue;
    pts.push_back(f.map_points[i]->p_w());
    obs.push_back(f.observation(i));
    idx.push_back(i);
  }
  std::fill(f.outlier.begin(), f.outlier.end(), 0);
  if (pts.size() < 3) return 0;
  const PoseOptimizerResult r = optimize_pose(f.T_c_w, pts, obs, f.cam->K);
  f.T_c_w = r.T_c_w;
  f.has_pose = true;
  for (std::size_t k = 0; k < idx.size(); ++k) f.outlier[idx[k]] = r.inlier[k] ? 0 : 1;
  return r.num_inliers;
}

}  // namespace pvb::slam
