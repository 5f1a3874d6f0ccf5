#pragma once
// The simulator side of a scenario run: what it hands to the consumer (a
// sensor frame and, beside it, the ground truth) and the producer that
// steps the physics, renders and applies the sensor model.
#include <Eigen/Core>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/robot.hpp"
#include "pvb/sim/sim_frame_source.hpp"

namespace pvb::run {

/// Closed loop: what the consumer (SLAM) tells the producer (simulator)
/// before the next physics step.
struct Steering {
  std::mutex mutex;
  bool hold = true;                 ///< not initialised or lost: stand still
  std::optional<sim::Pose2d> pose;  ///< the robot's pose as SLAM sees it (site frame)
};

/// One frame from the producer: the sensor frame for SLAM and, beside it
/// (never inside it), the ground truth for the harness.
struct FrameItem {
  sensor::RgbdFrame frame;
  geom::StampedPose gt;  ///< T_w_c of the frame, from the ground-truth sink
  sim::Pose2d base_gt;   ///< robot axle centre, ground truth
  std::vector<sim::ImuTruth> imu_truth;      ///< the truth behind frame.imu
  std::vector<sim::WheelTruth> wheel_truth;  ///< the truth behind frame.wheel_ticks
  sim::SimFrameSource::StageTimes times;
};

/// A frame between the render stage and the sensor-model stage.
struct RenderedItem {
  sim::RenderedFrame rendered;
  geom::StampedPose gt;
  sim::Pose2d base_gt;
  sim::SimFrameSource::StageTimes times;
};

/// The sensor-model stage: a pure function of the rendered frame (noise
/// seeded by scenario seed and frame index), so it gives the same frame on
/// whichever thread it runs.
FrameItem apply_sensor(const sim::SensorModel& sensor, RenderedItem&& item);

/// What the consumer needs to know about the simulator once it is built.
struct SimInfo {
  std::string renderer;
  std::vector<Eigen::Vector2d> route;
  sim::DriveKinematics kinematics;  ///< the drive's effective radius and track
  std::optional<sim::SensorModel> sensor;  ///< a copy, for the sensor-model thread
};

/// The simulator side: builds the scene and renderer on the thread that
/// will render (a GL context belongs to its thread), applies the closed-loop
/// steering before each physics step and hands rendered frames out.
class FrameProducer {
 public:
  /// steering: null in the open loop.
  FrameProducer(const scenes::Scenario& scenario, sim::GlBackend backend, int frames, Steering* steering);
  const SimInfo& info() const { return info_; }

  /// Steering, physics and rendering (the GL thread's part).
  std::optional<RenderedItem> next_rendered();

  /// Both stages on the calling thread.
  std::optional<FrameItem> next();

 private:
  sim::SimFrameSource source_;
  Steering* steering_;
  geom::StampedPose gt_;
  SimInfo info_;
};

}  // namespace pvb::run
