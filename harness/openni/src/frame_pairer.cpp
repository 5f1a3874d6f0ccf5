#include "pvb/openni/frame_pairer.hpp"

#include <cstdlib>

namespace pvb::openni {
namespace {
std::int64_t dist(std::int64_t a, std::int64_t b) { return a > b ? a - b : b - a; }
}  // namespace

FramePairer::FramePairer(std::int64_t tolerance_ns, std::size_t max_queue)
    : tolerance_ns_(tolerance_ns), max_queue_(max_queue < 2 ? 2 : max_queue) {}

void FramePairer::push_depth(TimedImage depth) {
  depth_.push_back(std::move(depth));
  while (depth_.size() > max_queue_) {
    depth_.pop_front();
    ++dropped_depth_;
  }
}

void FramePairer::push_colour(TimedImage colour) {
  colour_.push_back(std::move(colour));
  while (colour_.size() > max_queue_) {
    colour_.pop_front();
    ++dropped_colour_;
  }
}

std::optional<ImagePair> FramePairer::pop(bool end_of_stream) {
  while (!colour_.empty()) {
    const std::int64_t t_c = colour_.front().t_ns;
    // Depth images too old for this colour image are too old for every later one.
    while (!depth_.empty() && depth_.front().t_ns < t_c - tolerance_ns_) {
      depth_.pop_front();
      ++dropped_depth_;
    }
    // Keep the nearest at the front: drop a front image when its successor is at least as near.
    while (depth_.size() >= 2 && dist(depth_[1].t_ns, t_c) <= dist(depth_[0].t_ns, t_c)) {
      depth_.pop_front();
      ++dropped_depth_;
    }
    if (depth_.empty()) {
      if (!end_of_stream) return std::nullopt;
      colour_.pop_front();
      ++dropped_colour_;
      continue;
    }
    if (dist(depth_.front().t_ns, t_c) > tolerance_ns_) {
      // The nearest depth is later than t_c + tolerance: nothing can pair it.
      if (depth_.front().t_ns > t_c || end_of_stream) {
        colour_.pop_front();
        ++dropped_colour_;
        continue;
      }
      return std::nullopt;
    }
    const bool decided = end_of_stream || depth_.back().t_ns >= t_c;
    if (!decided) return std::nullopt;
    ImagePair pair{std::move(colour_.front()), std::move(depth_.front())};
    colour_.pop_front();
    depth_.pop_front();
    return pair;
  }
  return std::nullopt;
}

}  // namespace pvb::openni
