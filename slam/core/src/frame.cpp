#include "pvb/slam/core/frame.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <opencv2/calib3d.hpp>

#include "pvb/common/memory.hpp"
#include "pvb/common/popcount.hpp"

namespace pvb::slam {

CameraModel CameraModel::make(const StereoIntrinsics& K, int width, int height, const std::vector<double>& dist,
                              double th_depth_m, double scale_factor, int num_levels) {
  CameraModel c;
  c.K = K;
  c.width = width;
  c.height = height;
  c.th_depth_m = th_depth_m;
  c.K_cv = (cv::Mat_<double>(3, 3) << K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1);
  const bool distorted = std::any_of(dist.begin(), dist.end(), [](double d) { return d != 0; });
  if (distorted) c.dist_cv = cv::Mat(dist, true).reshape(1, 1);
  c.min_x = 0;
  c.max_x = width;
  c.min_y = 0;
  c.max_y = height;
  if (distorted) {
    std::vector<cv::Point2f> corners = {{0, 0}, {float(width), 0}, {0, float(height)}, {float(width), float(height)}};
    std::vector<cv::Point2f> un;
    cv::undistortPoints(corners, un, c.K_cv, c.dist_cv, cv::noArray(), c.K_cv);
    c.min_x = std::min(un[0].x, un[2].x);
    c.max_x = std::max(un[1].x, un[3].x);
    c.min_y = std::min(un[0].y, un[1].y);
    c.max_y = std::max(un[2].y, un[3].y);
    // One batch call for every pixel, so that keypoints moved after
    // detection (patch alignment) are undistorted without a call each.
    std::vector<cv::Point2f> px(static_cast<std::size_t>(width) * height);
    for (int v = 0; v < height; ++v)
      for (int u = 0; u < width; ++u) px[static_cast<std::size_t>(v) * width + u] = cv::Point2f(float(u), float(v));
    std::vector<cv::Point2f> px_un;
    cv::undistortPoints(px, px_un, c.K_cv, c.dist_cv, cv::noArray(), c.K_cv);
    c.undistort_table = cv::Mat(height, width, CV_32FC2);
    std::memcpy(c.undistort_table.data, px_un.data(), px_un.size() * sizeof(cv::Point2f));
  }
  c.grid_inv_w = kGridCols / (c.max_x - c.min_x);
  c.grid_inv_h = kGridRows / (c.max_y - c.min_y);
  c.num_levels = num_levels;
  c.log_scale_factor = std::log(scale_factor);
  double s = 1.0;
  for (int l = 0; l < num_levels; ++l) {
    c.scale.push_back(s);
    c.level_sigma2.push_back(s * s);
    c.inv_level_sigma2.push_back(1.0 / (s * s));
    s *= scale_factor;
  }
  return c;
}

Eigen::Vector2d CameraModel::undistort(const Eigen::Vector2d& px) const {
  if (undistort_table.empty()) return px;
  const double x = std::clamp(px.x(), 0.0, double(width - 1)), y = std::clamp(px.y(), 0.0, double(height - 1));
  const int u0 = std::min(static_cast<int>(x), width - 2), v0 = std::min(static_cast<int>(y), height - 2);
  const double a = x - u0, b = y - v0;
  const auto at = [&](int v, int u) {
    const cv::Vec2f& p = undistort_table.at<cv::Vec2f>(v, u);
    return Eigen::Vector2d(p[0], p[1]);
  };
  return (1 - b) * ((1 - a) * at(v0, u0) + a * at(v0, u0 + 1)) + b * ((1 - a) * at(v0 + 1, u0) + a * at(v0 + 1, u0 + 1));
}

int CameraModel::predict_scale(double dist_m, double max_dist_m) const {
  const double ratio = max_dist_m / dist_m;
  int level = static_cast<int>(std::ceil(std::log(ratio) / log_scale_factor));
  return std::clamp(level, 0, num_levels - 1);
}

namespace {

/// Counting sort of the keypoints by cell: start[c] is where cell c's
/// indices begin in `index`, each cell's in ascending order.
template <typename T>
void group_by_cell(const std::vector<int>& cell_of, int num_cells, FeatureArray<T>* start, FeatureArray<T>* index) {
  start->assign(static_cast<std::size_t>(num_cells) + 1, 0);
  for (int c : cell_of)
    if (c >= 0) ++(*start)[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 1; c < start->size(); ++c) (*start)[c] = static_cast<T>((*start)[c] + (*start)[c - 1]);
  index->resize(start->back());
  std::vector<T> next(start->begin(), start->end() - 1);
  for (std::size_t i = 0; i < cell_of.size(); ++i)
    if (cell_of[i] >= 0) (*index)[next[static_cast<std::size_t>(cell_of[i])]++] = static_cast<T>(i);
}

}  // namespace

KeypointGrid::KeypointGrid(const std::vector<int>& cell_of, int num_cells) {
  if (cell_of.size() <= std::numeric_limits<std::uint16_t>::max())
    group_by_cell(cell_of, num_cells, &start16_, &index16_);
  else
    group_by_cell(cell_of, num_cells, &start32_, &index32_);
}

std::size_t KeypointGrid::memory_bytes() const {
  return feature_heap_bytes(start16_) + feature_heap_bytes(index16_) + feature_heap_bytes(start32_) +
         feature_heap_bytes(index32_);
}

std::size_t KeypointGrid::spilled_bytes() const {
  return feature_spilled_bytes(start16_) + feature_spilled_bytes(index16_) + feature_spilled_bytes(start32_) +
         feature_spilled_bytes(index32_);
}

void KeypointGrid::spill_to(FeatureSpill* spill) {
  start16_ = spilled_copy(start16_, spill);
  index16_ = spilled_copy(index16_, spill);
  start32_ = spilled_copy(start32_, spill);
  index32_ = spilled_copy(index32_, spill);
}

Frame::Frame(std::uint64_t frame_id, std::int64_t time_ns, OrbFeatures features, const cv::Mat& depth,
             std::shared_ptr<const CameraModel> camera)
    : id(frame_id), t_ns(time_ns), cam(std::move(camera)) {
  descriptors = features.descriptors;
  const std::size_t n = features.keypoints.size();
  keys.resize(n);
  keys_un.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const cv::KeyPoint& k = features.keypoints[i];
    keys[i] = k.pt;
    keys_un[i] = Keypoint{k.pt, k.angle, k.octave};
  }
  if (!cam->dist_cv.empty() && n > 0) {
    const cv::Mat detected(static_cast<int>(n), 1, CV_32FC2, keys.data());  // a view, no copy
    std::vector<cv::Point2f> un;
    cv::undistortPoints(detected, un, cam->K_cv, cam->dist_cv, cv::noArray(), cam->K_cv);
    for (std::size_t i = 0; i < n; ++i) keys_un[i].pt = un[i];
  }
  depth_m.assign(n, -1.0f);
  u_right.assign(n, -1.0f);
  for (std::size_t i = 0; i < n; ++i) {
    // depth is read at the distorted (image) position, as ORB-SLAM2 does
    const int u = static_cast<int>(std::lround(keys[i].x));
    const int v = static_cast<int>(std::lround(keys[i].y));
    if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) continue;
    const float d = depth.at<float>(v, u);
    if (d > 0 && std::isfinite(d)) {
      depth_m[i] = d;
      u_right[i] = right_coordinate(keys_un[i].pt.x, d);
    }
  }
  build_index();
}

Frame Frame::from_saved(std::uint64_t frame_id, std::int64_t time_ns, std::vector<cv::Point2f> keys_detected,
                        std::vector<Keypoint> keys_undistorted, cv::Mat descriptors, std::vector<float> depth,
                        std::shared_ptr<const CameraModel> camera) {
  Frame f;
  f.id = frame_id;
  f.t_ns = time_ns;
  f.cam = std::move(camera);
  f.keys.assign(keys_detected.begin(), keys_detected.end());
  f.keys_un.assign(keys_undistorted.begin(), keys_undistorted.end());
  f.descriptors = std::move(descriptors);
  f.depth_m.assign(depth.begin(), depth.end());
  f.u_right.assign(f.keys_un.size(), -1.0f);
  for (std::size_t i = 0; i < f.keys_un.size(); ++i)
    if (f.depth_m[i] > 0) f.u_right[i] = f.right_coordinate(f.keys_un[i].pt.x, f.depth_m[i]);
  f.build_index();
  return f;
}

void Frame::build_index() {
  const std::size_t n = keys_un.size();
  map_points.assign(n, nullptr);
  outlier.assign(n, 0);
  aligned_for.assign(n, kNotAligned);
  std::vector<int> cell_of(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const int cx = static_cast<int>(std::floor((keys_un[i].pt.x - cam->min_x) * cam->grid_inv_w));
    const int cy = static_cast<int>(std::floor((keys_un[i].pt.y - cam->min_y) * cam->grid_inv_h));
    if (cx < 0 || cy < 0 || cx >= CameraModel::kGridCols || cy >= CameraModel::kGridRows) continue;
    cell_of[i] = cy * CameraModel::kGridCols + cx;
  }
  grid_ = KeypointGrid(cell_of, CameraModel::kGridCols * CameraModel::kGridRows);
}

std::vector<std::size_t> Frame::features_in_area(double u, double v, double r, int min_level, int max_level) const {
  std::vector<std::size_t> out;
  features_in_area(u, v, r, min_level, max_level, &out);
  return out;
}

void Frame::features_in_area(double u, double v, double r, int min_level, int max_level,
                             std::vector<std::size_t>* result) const {
  std::vector<std::size_t>& out = *result;
  out.clear();
  const int c0 = std::max(0, static_cast<int>(std::floor((u - cam->min_x - r) * cam->grid_inv_w)));
  const int c1 = std::min(CameraModel::kGridCols - 1, static_cast<int>(std::ceil((u - cam->min_x + r) * cam->grid_inv_w)));
  const int r0 = std::max(0, static_cast<int>(std::floor((v - cam->min_y - r) * cam->grid_inv_h)));
  const int r1 = std::min(CameraModel::kGridRows - 1, static_cast<int>(std::ceil((v - cam->min_y + r) * cam->grid_inv_h)));
  if (c0 > c1 || r0 > r1 || grid_.empty()) return;
  for (int gy = r0; gy <= r1; ++gy)
    for (int gx = c0; gx <= c1; ++gx)
      grid_.for_each_in_cell(gy * CameraModel::kGridCols + gx, [&](std::size_t i) {
        const Keypoint& k = keys_un[i];
        if (min_level >= 0 && k.octave < min_level) return;
        if (max_level >= 0 && k.octave > max_level) return;
        const double dx = k.pt.x - u, dy = k.pt.y - v;
        if (std::abs(dx) < r && std::abs(dy) < r) out.push_back(i);
      });
  std::sort(out.begin(), out.end());
}

int Frame::num_with_depth() const {
  return static_cast<int>(std::count_if(depth_m.begin(), depth_m.end(), [](float d) { return d > 0; }));
}

std::vector<std::pair<float, std::size_t>> Frame::keypoints_by_depth() const {
  std::vector<std::pair<float, std::size_t>> by_depth;
  for (std::size_t i = 0; i < size(); ++i)
    if (depth_m[i] > 0) by_depth.emplace_back(depth_m[i], i);
  std::sort(by_depth.begin(), by_depth.end());
  return by_depth;
}

Eigen::Vector3d Frame::unproject_world(std::size_t i) const {
  return T_c_w.inverse() * cam->unproject(Eigen::Vector2d(keys_un[i].pt.x, keys_un[i].pt.y), depth_m[i]);
}

void Frame::move_keypoint(std::size_t i, const Eigen::Vector2d& to_px) {
  const Eigen::Vector2d shift = to_px - Eigen::Vector2d(keys[i].x, keys[i].y);
  keys[i].x = static_cast<float>(to_px.x());
  keys[i].y = static_cast<float>(to_px.y());
  if (cam->undistort_table.empty()) {
    keys_un[i].pt.x += static_cast<float>(shift.x());
    keys_un[i].pt.y += static_cast<float>(shift.y());
  } else {
    const Eigen::Vector2d un = cam->undistort(to_px);
    keys_un[i].pt.x = static_cast<float>(un.x());
    keys_un[i].pt.y = static_cast<float>(un.y());
  }
  if (depth_m[i] > 0) u_right[i] = right_coordinate(keys_un[i].pt.x, depth_m[i]);
}

Observation Frame::observation(std::size_t i) const {
  Observation o;
  o.uv = Eigen::Vector2d(keys_un[i].pt.x, keys_un[i].pt.y);
  o.u_right = u_right[i];
  o.inv_sigma2 = cam->inv_level_sigma2[keys_un[i].octave];
  return o;
}

FrameMemory& FrameMemory::operator+=(const FrameMemory& o) {
  pyramid += o.pyramid;
  keypoints += o.keypoints;
  descriptors += o.descriptors;
  per_keypoint += o.per_keypoint;
  grid += o.grid;
  object += o.object;
  spilled += o.spilled;
  return *this;
}

std::size_t mat_heap_bytes(const cv::Mat& m) {
  if (m.u == nullptr) return 0;
  // cv::fastMalloc asks for a pointer and 64 bytes more, to align the data to 64.
  constexpr std::size_t kAlignSlack = sizeof(void*) + 64;
  return heap_block_bytes(m.u->size + kAlignSlack) + heap_block_bytes(sizeof(cv::UMatData));
}

void Frame::release_features() {
  FeatureArray<cv::Point2f>().swap(keys);
  FeatureArray<Keypoint>().swap(keys_un);
  descriptors.release();
  FeatureArray<float>().swap(depth_m);
  FeatureArray<float>().swap(u_right);
  std::vector<std::shared_ptr<MapPoint>>().swap(map_points);
  std::vector<std::uint8_t>().swap(outlier);
  std::vector<std::uint64_t>().swap(aligned_for);
  grid_ = KeypointGrid();
  pyramid.reset();
  spill_.reset();
}

void Frame::spill_features(const std::shared_ptr<FeatureSpill>& spill) {
  if (!spill || spill_ || keys_un.empty()) return;
  FeatureSpill* s = spill.get();
  keys = spilled_copy(keys, s);
  keys_un = spilled_copy(keys_un, s);
  depth_m = spilled_copy(depth_m, s);
  u_right = spilled_copy(u_right, s);
  grid_.spill_to(s);
  if (!descriptors.empty()) {
    cv::Mat d;
    d.allocator = s->mat_allocator();
    d.create(descriptors.rows, descriptors.cols, descriptors.type());
    if (descriptors.isContinuous())
      s->store(d.data, descriptors.data, descriptors.total() * descriptors.elemSize());  // through the file
    else
      descriptors.copyTo(d);
    descriptors = d;
  }
  spill_ = spill;
}

void Frame::release_pyramid() {
  pyramid.reset();
  std::vector<std::uint64_t>().swap(aligned_for);
}

FrameMemory Frame::memory() const {
  FrameMemory m;
  if (pyramid) {
    // make_shared: the vector and its control block in one block
    m.pyramid = heap_block_bytes(sizeof(ImagePyramid) + 2 * sizeof(long)) + vector_heap_bytes(*pyramid);
    for (const cv::Mat& level : *pyramid) m.pyramid += mat_heap_bytes(level);
  }
  m.keypoints = feature_heap_bytes(keys) + feature_heap_bytes(keys_un);
  const bool descriptors_spilled = spill_ && descriptors.u && descriptors.u->currAllocator == spill_->mat_allocator();
  m.descriptors = descriptors_spilled ? 0 : mat_heap_bytes(descriptors);
  m.per_keypoint = feature_heap_bytes(depth_m) + feature_heap_bytes(u_right) + vector_heap_bytes(map_points) +
                   vector_heap_bytes(outlier) + vector_heap_bytes(aligned_for);
  m.grid = grid_.memory_bytes();
  m.spilled = feature_spilled_bytes(keys) + feature_spilled_bytes(keys_un) + feature_spilled_bytes(depth_m) +
              feature_spilled_bytes(u_right) + grid_.spilled_bytes() +
              (descriptors_spilled ? descriptors.u->size : 0);
  m.object = sizeof(Frame);
  return m;
}

int descriptor_distance(const unsigned char* a, const unsigned char* b) {
  int d = 0;
  for (int k = 0; k < 32; k += 8) {
    std::uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    d += popcount64(x ^ y);
  }
  return d;
}

int descriptor_distance(const cv::Mat& a, const cv::Mat& b) { return descriptor_distance(a.ptr<unsigned char>(0), b.ptr<unsigned char>(0)); }

}  // namespace pvb::slam
