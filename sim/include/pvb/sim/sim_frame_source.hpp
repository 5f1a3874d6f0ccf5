#pragma once
// The simulator as a live frame source: frames go to SLAM in memory through
// the same FrameSource interface as recorded datasets.  Ground truth does not
// travel with the frames: it goes to a separate sink the harness provides.
#include <functional>
#include <memory>

#include "pvb/geometry/stamped_pose.hpp"
#include "pvb/sensor/frame_source.hpp"
#include "pvb/sim/simulator.hpp"

namespace pvb::sim {

class SimFrameSource : public sensor::FrameSource {
 public:
  /// Receives the ground-truth camera pose of each frame, before next()
  /// returns that frame.
  using GroundTruthSink = std::function<void(const geom::StampedPose& T_w_c)>;

  /// Builds the simulator and its camera.  max_frames > 0 caps the stream.
  SimFrameSource(scenes::Scenario scenario, GlBackend backend, int max_frames = 0, GroundTruthSink sink = {});

  /// Advances the physics by one camera period (not before frame 0),
  /// renders and applies the sensor model.  nullopt after the last frame.
  std::optional<sensor::RgbdFrame> next() override;
  /// The simulator's half of next(): advances, renders and sends the ground
  /// truth to the sink, without the sensor model.  For pipelines that run
  /// sensor_model().apply() on another thread; next() is both halves.
  std::optional<RenderedFrame> next_rendered();
  /// Advances the physics by one camera period without rendering, for
  /// frames a consumer does not use (no ground truth goes to the sink).
  /// The frames after it are those next() would have given: the sensor
  /// noise is seeded per frame.  False after the last frame.
  bool skip();
  const SensorModel& sensor_model() const { return camera_.sensor_model(); }
  std::size_t size_hint() const override { return static_cast<std::size_t>(frames_); }
  std::string describe() const override;

  /// The simulator, for closed-loop steering and reports.
  Simulator& simulator() { return sim_; }
  const RgbdCamera& camera() const { return camera_; }
  /// Rendered (noise-free) depth of the last frame, for diagnostics.
  const cv::Mat& last_depth_gt_m() const { return last_depth_gt_m_; }
  /// The truth behind the last next() frame's IMU and encoder readings.
  const std::vector<ImuTruth>& last_imu_truth() const { return last_imu_truth_; }
  const std::vector<WheelTruth>& last_wheel_truth() const { return last_wheel_truth_; }

  /// Where the time of the last next() went, milliseconds.
  struct StageTimes {
    double physics_ms = 0;  ///< Simulator::advance (steering + physics steps)
    double render_ms = 0;   ///< GL rendering and read-back
    double sensor_ms = 0;   ///< depth and RGB sensor model
    double stereo_match_ms = 0;  ///< the d435 model's semi-global matching (part of sensor_ms)
  };
  const StageTimes& last_stage_times() const { return last_times_; }

 private:
  Simulator sim_;
  RgbdCamera camera_;
  int frames_;
  int next_index_ = 0;
  GroundTruthSink sink_;
  cv::Mat last_depth_gt_m_;
  std::vector<ImuTruth> last_imu_truth_;
  std::vector<WheelTruth> last_wheel_truth_;
  StageTimes last_times_;
};

}  // namespace pvb::sim
