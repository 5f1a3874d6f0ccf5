#include "pvb/sim/sim_frame_source.hpp"

#include <chrono>

namespace pvb::sim {

SimFrameSource::SimFrameSource(scenes::Scenario scenario, GlBackend backend, int max_frames, GroundTruthSink sink)
    : sim_(std::move(scenario)),
      camera_(sim_, backend),
      frames_(scenes::frame_count(sim_.scenario(), max_frames)),
      sink_(std::move(sink)) {}

std::optional<RenderedFrame> SimFrameSource::next_rendered() {
  if (next_index_ >= frames_) return std::nullopt;
  const auto t0 = std::chrono::steady_clock::now();
  if (next_index_ > 0) sim_.advance();
  last_times_.physics_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++next_index_;
  RenderedFrame rendered = camera_.render(sim_);
  last_times_.render_ms = rendered.render_ms;
  last_times_.sensor_ms = 0;
  last_times_.stereo_match_ms = 0;
  if (sink_) sink_({rendered.t_ns, rendered.T_w_c});
  return rendered;
}

bool SimFrameSource::skip() {
  if (next_index_ >= frames_) return false;
  if (next_index_ > 0) sim_.advance();
  ++next_index_;
  return true;
}

std::optional<sensor::RgbdFrame> SimFrameSource::next() {
  std::optional<RenderedFrame> rendered = next_rendered();
  if (!rendered) return std::nullopt;
  Capture cap = camera_.sensor_model().apply(std::move(*rendered));
  last_times_.sensor_ms = cap.sensor_ms;
  last_times_.stereo_match_ms = cap.stereo.match_ms;
  last_depth_gt_m_ = cap.depth_gt_m;
  last_imu_truth_ = std::move(cap.imu_truth);
  last_wheel_truth_ = std::move(cap.wheel_truth);
  return std::move(cap.frame);
}

std::string SimFrameSource::describe() const {
  return "sim:" + sim_.scenario().name + " (seed " + std::to_string(sim_.scenario().seed) + ", " +
         camera_.description() + ")";
}

}  // namespace pvb::sim
