#include "frame_producer.hpp"

namespace pvb::run {

FrameItem apply_sensor(const sim::SensorModel& sensor, RenderedItem&& item) {
  sim::Capture cap = sensor.apply(std::move(item.rendered));
  item.times.sensor_ms = cap.sensor_ms;
  return FrameItem{std::move(cap.frame), item.gt, item.base_gt, std::move(cap.imu_truth),
                   std::move(cap.wheel_truth), item.times};
}

FrameProducer::FrameProducer(const scenes::Scenario& scenario, sim::GlBackend backend, int frames,
                             Steering* steering)
    : source_(scenario, backend, frames, [this](const geom::StampedPose& p) { gt_ = p; }),
      steering_(steering) {
  info_.renderer = source_.camera().description();
  info_.route = source_.simulator().follower().path();
  info_.kinematics = source_.simulator().kinematics();
  info_.sensor = source_.sensor_model();
}

std::optional<RenderedItem> FrameProducer::next_rendered() {
  sim::Simulator& sim = source_.simulator();
  if (steering_) {
    std::lock_guard<std::mutex> lock(steering_->mutex);
    sim.set_hold(steering_->hold);
    sim.set_steering_pose(steering_->pose);
  }
  std::optional<sim::RenderedFrame> r = source_.next_rendered();
  if (!r) return std::nullopt;
  return RenderedItem{std::move(*r), gt_, sim.base_pose(), source_.last_stage_times()};
}

std::optional<FrameItem> FrameProducer::next() {
  std::optional<RenderedItem> r = next_rendered();
  if (!r) return std::nullopt;
  return apply_sensor(source_.sensor_model(), std::move(*r));
}

}  // namespace pvb::run
