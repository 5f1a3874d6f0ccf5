#pragma once
// Closed-loop steering: after each frame, the robot's pose as SLAM sees it
// goes back to the route follower (or the robot holds while SLAM is not
// initialised or lost), and the ground-truth robot's distance from the
// route is recorded.
#include <Eigen/Core>
#include <vector>

#include "frame_producer.hpp"
#include "pvb/geometry/se3.hpp"
#include "pvb/report/report.hpp"
#include "pvb/run/run.hpp"
#include "pvb/slam/core/system.hpp"

namespace pvb::run {

class ClosedLoop {
 public:
  /// What the producer reads before each physics step.
  Steering* steering() { return &steering_; }

  /// The route the follower drives (known once the simulator is built).
  void set_route(std::vector<Eigen::Vector2d> route) { route_ = std::move(route); }

  /// Frame `item` was tracked by the primary system with result `r`:
  /// records the path error and steers from the SLAM pose, or holds.
  void update(const FrameItem& item, const slam::FrameResult& r);

  /// The path errors with their rmse and max.
  ClosedLoopMetrics metrics() const;

 private:
  Steering steering_;
  ClosedLoopMetrics metrics_;
  std::vector<Eigen::Vector2d> route_;
  CameraMount mount_;
  geom::SE3d T_site_slam_ = geom::SE3d::Identity();  ///< SLAM world (first camera frame) in the site frame
};

}  // namespace pvb::run
