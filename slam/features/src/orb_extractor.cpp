#include "pvb/slam/features/orb_extractor.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "pvb/common/error.hpp"

namespace pvb::slam {
namespace {

constexpr int kPatchSize = 31;       ///< rBRIEF / orientation patch diameter, px
constexpr int kHalfPatchSize = 15;   ///< orientation patch radius, px
constexpr int kEdgeThreshold = 19;   ///< pyramid border, px (ORB-SLAM2 EDGE_THRESHOLD)
constexpr int kCellSizePx = 30;      ///< FAST grid cell size, px (ORB-SLAM2 W)
constexpr int kFastBorderPx = 3;     ///< FAST circle radius, px

const int kBitPattern31[256 * 4] = {
#include "orb_pattern.inc"
};

/// A quadtree node over a rectangle of the detection area.
struct QuadNode {
  cv::Point2f ul, br;         ///< upper-left and bottom-right corners
  std::vector<int> keys;      ///< indices into the level's corner list
};

/// Splits a node into its four quadrants; empty children are dropped.
void split_node(const QuadNode& n, const std::vector<cv::KeyPoint>& kps, std::vector<QuadNode>& out) {
  const float hx = 0.5f * (n.ul.x + n.br.x);
  const float hy = 0.5f * (n.ul.y + n.br.y);
  QuadNode c[4];
  c[0].ul = n.ul;               c[0].br = {hx, hy};
  c[1].ul = {hx, n.ul.y};       c[1].br = {n.br.x, hy};
  c[2].ul = {n.ul.x, hy};       c[2].br = {hx, n.br.y};
  c[3].ul = {hx, hy};           c[3].br = n.br;
  for (int k : n.keys) {
    const cv::Point2f& p = kps[k].pt;
    const int q = (p.x < hx ? 0 : 1) + (p.y < hy ? 0 : 2);
    c[q].keys.push_back(k);
  }
  for (auto& ch : c)
    if (!ch.keys.empty()) out.push_back(std::move(ch));
}

/// The detection area's first nodes: as many side by side as it is wider
/// than high (at least one), each with its corners; empty ones dropped.
std::vector<QuadNode> initial_nodes(const std::vector<cv::KeyPoint>& kps, float min_x, float max_x, float min_y,
                                    float max_y) {
  const float width = max_x - min_x;
  const float height = max_y - min_y;
  const int num_ini = std::max(1, static_cast<int>(std::lround(width / height)));
  const float hx = width / num_ini;

  std::vector<QuadNode> nodes(num_ini);
  for (int i = 0; i < num_ini; ++i) {
    nodes[i].ul = {min_x + hx * i, min_y};
    nodes[i].br = {min_x + hx * (i + 1), max_y};
  }
  for (int k = 0; k < static_cast<int>(kps.size()); ++k) {
    const int i = std::clamp(static_cast<int>((kps[k].pt.x - min_x) / hx), 0, num_ini - 1);
    nodes[i].keys.push_back(k);
  }
  nodes.erase(std::remove_if(nodes.begin(), nodes.end(), [](const QuadNode& n) { return n.keys.empty(); }),
              nodes.end());
  return nodes;
}

/// Whether a node can split: a node with one corner, or one too small to
/// split further, stays.
bool splittable(const QuadNode& n) {
  return n.keys.size() > 1 && (n.br.x - n.ul.x) > 1.0f && (n.br.y - n.ul.y) > 1.0f;
}

/// Splits every splittable node once, in order; returns how many of the
/// new nodes are splittable themselves.
int split_all(std::vector<QuadNode>& nodes, const std::vector<cv::KeyPoint>& kps) {
  std::vector<QuadNode> next;
  int to_expand = 0;
  for (QuadNode& n : nodes) {
    if (!splittable(n)) {
      next.push_back(std::move(n));
      continue;
    }
    const size_t before = next.size();
    split_node(n, kps, next);
    for (size_t c = before; c < next.size(); ++c)
      if (splittable(next[c])) ++to_expand;
  }
  nodes.swap(next);
  return to_expand;
}

/// Near the target: splits the most populated nodes first, one at a time,
/// until there are `num_wanted` nodes or nothing splits any more.
void split_most_populated(std::vector<QuadNode>& nodes, const std::vector<cv::KeyPoint>& kps, int num_wanted) {
  std::vector<QuadNode> next;
  bool finished = false;
  while (!finished) {
    const size_t size_before = nodes.size();
    std::vector<size_t> order;
    for (size_t i = 0; i < nodes.size(); ++i)
      if (splittable(nodes[i])) order.push_back(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return nodes[a].keys.size() > nodes[b].keys.size(); });
    std::vector<bool> removed(nodes.size(), false);
    std::vector<QuadNode> added;
    int count = static_cast<int>(nodes.size());
    for (size_t i : order) {
      const size_t before = added.size();
      split_node(nodes[i], kps, added);
      removed[i] = true;
      count += static_cast<int>(added.size() - before) - 1;
      if (count >= num_wanted) break;
    }
    next.clear();
    for (size_t i = 0; i < nodes.size(); ++i)
      if (!removed[i]) next.push_back(std::move(nodes[i]));
    for (auto& a : added) next.push_back(std::move(a));
    nodes.swap(next);
    if (static_cast<int>(nodes.size()) >= num_wanted || nodes.size() == size_before) finished = true;
  }
}

/// ORB-SLAM2's DistributeOctTree: splits the detection area in a quadtree
/// until there are at least `num_wanted` non-empty nodes (or nothing can be
/// split any more) and keeps the strongest corner of every node.
std::vector<cv::KeyPoint> distribute_quadtree(const std::vector<cv::KeyPoint>& kps, float min_x,
                                              float max_x, float min_y, float max_y,
                                              int num_wanted) {
  if (kps.empty() || num_wanted <= 0) return {};
  std::vector<QuadNode> nodes = initial_nodes(kps, min_x, max_x, min_y, max_y);
  while (true) {
    const size_t prev_size = nodes.size();
    const int to_expand = split_all(nodes, kps);
    if (static_cast<int>(nodes.size()) >= num_wanted || nodes.size() == prev_size) break;
    if (static_cast<int>(nodes.size()) + 3 * to_expand > num_wanted) {
      split_most_populated(nodes, kps, num_wanted);
      break;
    }
  }

  std::vector<cv::KeyPoint> out;
  out.reserve(nodes.size());
  for (const QuadNode& n : nodes) {
    int best = n.keys.front();
    for (int k : n.keys)
      if (kps[k].response > kps[best].response) best = k;
    out.push_back(kps[best]);
  }
  return out;
}

}  // namespace

std::vector<int> circular_patch_umax(int half_patch) {
  std::vector<int> umax(half_patch + 1);
  const int vmax = static_cast<int>(std::floor(half_patch * std::sqrt(2.0) / 2 + 1));
  const int vmin = static_cast<int>(std::ceil(half_patch * std::sqrt(2.0) / 2));
  const double hp2 = static_cast<double>(half_patch) * half_patch;
  for (int v = 0; v <= std::min(vmax, half_patch); ++v) umax[v] = static_cast<int>(std::lround(std::sqrt(hp2 - v * v)));
  // Make the circle symmetric about the diagonal.
  for (int v = half_patch, v0 = 0; v >= vmin; --v) {
    while (umax[v0] == umax[v0 + 1]) ++v0;
    umax[v] = v0;
    ++v0;
  }
  return umax;
}

float ic_angle_deg(const cv::Mat& image, cv::Point2f pt, const std::vector<int>& umax) {
  const int half = static_cast<int>(umax.size()) - 1;
  const uchar* center = &image.at<uchar>(cvRound(pt.y), cvRound(pt.x));
  const int step = static_cast<int>(image.step1());
  int m01 = 0, m10 = 0;
  for (int u = -half; u <= half; ++u) m10 += u * center[u];
  for (int v = 1; v <= half; ++v) {
    int v_sum = 0;
    const int d = umax[v];
    for (int u = -d; u <= d; ++u) {
      const int plus = center[u + v * step], minus = center[u - v * step];
      v_sum += plus - minus;
      m10 += u * (plus + minus);
    }
    m01 += v * v_sum;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

void compute_rbrief(const cv::Mat& image, const cv::KeyPoint& kp, unsigned char* desc32) {
  assert(image.type() == CV_8UC1);
  const float angle_rad = kp.angle * static_cast<float>(CV_PI / 180.0);
  const float a = std::cos(angle_rad), b = std::sin(angle_rad);
  const uchar* center = &image.at<uchar>(cvRound(kp.pt.y), cvRound(kp.pt.x));
  const int step = static_cast<int>(image.step);
  // Value at pattern point (x, y) rotated by the keypoint angle.
  auto value = [&](int px, int py) {
    const int ix = cvRound(px * a - py * b);
    const int iy = cvRound(px * b + py * a);
    return center[iy * step + ix];
  };
  const int* p = kBitPattern31;
  for (int byte = 0; byte < 32; ++byte) {
    int val = 0;
    for (int bit = 0; bit < 8; ++bit, p += 4) val |= (value(p[0], p[1]) < value(p[2], p[3])) << bit;
    desc32[byte] = static_cast<unsigned char>(val);
  }
}

int fast9_score(const cv::Mat& grey, int x, int y) {
  assert(grey.type() == CV_8UC1);
  // Bresenham circle of radius 3, clockwise from the top.
  static constexpr int kDx[16] = {0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3, -3, -3, -2, -1};
  static constexpr int kDy[16] = {-3, -3, -2, -1, 0, 1, 2, 3, 3, 3, 2, 1, 0, -1, -2, -3};
  const int centre = grey.at<uchar>(y, x);
  // The circle's differences to the centre, wrapped so that every arc of 9
  // is contiguous: arc s is diff[s .. s + 8].
  std::int16_t diff[25];
  for (int i = 0; i < 16; ++i)
    diff[i] = static_cast<std::int16_t>(grey.at<uchar>(y + kDy[i], x + kDx[i]) - centre);
  for (int i = 16; i < 25; ++i) diff[i] = diff[i - 16];
  // Arc s passes t when all of it is brighter than centre + t (t < lo[s])
  // or all darker than centre - t (t < -hi[s]); eight arcs per vector.
  int best = 0;
  for (int half = 0; half < 16; half += 8) {
    cv::v_int16x8 lo = cv::v_load(diff + half), hi = lo;
    for (int k = 1; k < 9; ++k) {
      const cv::v_int16x8 d = cv::v_load(diff + half + k);
      lo = cv::v_min(lo, d);
      hi = cv::v_max(hi, d);
    }
    best = std::max(best, std::max<int>(cv::v_reduce_max(lo), -cv::v_reduce_min(hi)));
  }
  return std::max(best - 1, 0);
}

cv::Point2f quadratic_peak_offset(const float s[3][3]) {
  const double gx = 0.5 * (s[1][2] - s[1][0]);
  const double gy = 0.5 * (s[2][1] - s[0][1]);
  const double hxx = s[1][2] - 2.0 * s[1][1] + s[1][0];
  const double hyy = s[2][1] - 2.0 * s[1][1] + s[0][1];
  const double hxy = 0.25 * (s[2][2] - s[2][0] - s[0][2] + s[0][0]);
  const double det = hxx * hyy - hxy * hxy;
  // A maximum needs a negative-definite Hessian.
  if (!(hxx < 0 && det > 0)) return {0.f, 0.f};
  const double dx = -(hyy * gx - hxy * gy) / det;
  const double dy = -(hxx * gy - hxy * gx) / det;
  return {static_cast<float>(std::clamp(dx, -0.5, 0.5)),
          static_cast<float>(std::clamp(dy, -0.5, 0.5))};
}

namespace {

/// The image as 8-bit grey (a view of it when it is grey already).
/// OpenCV's border copy spins for ever on an empty image (an image file
/// that did not load), so what cannot be a camera image is an error.
cv::Mat grey_image(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw Error("ORB extraction: expected an 8-bit grey, BGR or BGRA image, got " +
                (image.empty() ? std::string("an empty one (an image that did not load?)")
                               : std::to_string(image.cols) + "x" + std::to_string(image.rows) + " with " +
                                     std::to_string(image.channels()) + " channels of depth " +
                                     std::to_string(image.depth())));
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4)
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  else
    grey = image;
  assert(grey.type() == CV_8UC1);
  return grey;
}

/// The sub-pixel offset of corner kp of `level` (level pixels): the peak
/// of a quadratic through the FAST scores of its 3x3 neighbourhood.
/// Orientation and descriptor stay at the whole pixel; only the position
/// moves.  FAST keeps 3 px off its 16 px-inset detection area, so the 3x3
/// neighbourhood's circles stay inside the level.  The centre's score is
/// the corner's own FAST response.
cv::Point2f sub_pixel_offset(const cv::Mat& level, const cv::KeyPoint& kp) {
  const int x = cvRound(kp.pt.x), y = cvRound(kp.pt.y);
  float score[3][3];
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      score[dy + 1][dx + 1] = dx == 0 && dy == 0 ? kp.response : static_cast<float>(fast9_score(level, x + dx, y + dy));
  return quadratic_peak_offset(score);
}

/// The `num_features` strongest of `all`'s keypoints (the first of equal
/// responses), with their descriptors, in their order in `all`.
OrbFeatures strongest(const OrbFeatures& all, int num_features) {
  const int total = static_cast<int>(all.keypoints.size());
  std::vector<int> order(total);
  for (int i = 0; i < total; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return all.keypoints[a].response > all.keypoints[b].response; });
  order.resize(num_features);
  std::sort(order.begin(), order.end());
  OrbFeatures capped;
  capped.descriptors.create(num_features, 32, CV_8U);
  for (int i = 0; i < num_features; ++i) {
    capped.keypoints.push_back(all.keypoints[order[i]]);
    all.descriptors.row(order[i]).copyTo(capped.descriptors.row(i));
  }
  return capped;
}

}  // namespace

OrbExtractor::OrbExtractor(const OrbParams& params) : params_(params) {
  const int n = params_.num_levels;
  scales_.resize(n);
  scales_[0] = 1.0;
  for (int l = 1; l < n; ++l) scales_[l] = scales_[l - 1] * params_.scale_factor;

  // Geometric split of the features over the levels (ORB-SLAM2).
  features_per_level_.resize(n);
  const double factor = 1.0 / params_.scale_factor;
  double per_scale = params_.num_features * (1 - factor) / (1 - std::pow(factor, n));
  int sum = 0;
  for (int l = 0; l < n - 1; ++l) {
    features_per_level_[l] = static_cast<int>(std::lround(per_scale));
    sum += features_per_level_[l];
    per_scale *= factor;
  }
  features_per_level_[n - 1] = std::max(params_.num_features - sum, 0);
  umax_ = circular_patch_umax(kHalfPatchSize);
  pyramid_.resize(n);
  padded_.resize(n);
}

void OrbExtractor::build_pyramid(const cv::Mat& grey) {
  for (int l = 0; l < params_.num_levels; ++l) {
    const double s = 1.0 / scales_[l];
    // At least a pixel: a tiny image's coarse levels would round to none
    // (they give no features either way).
    const cv::Size sz(std::max(1, static_cast<int>(std::lround(grey.cols * s))),
                      std::max(1, static_cast<int>(std::lround(grey.rows * s))));
    cv::Mat level;
    if (l == 0)
      level = grey;
    else
      cv::resize(pyramid_[l - 1], level, sz, 0, 0, cv::INTER_LINEAR);
    cv::copyMakeBorder(level, padded_[l], kEdgeThreshold, kEdgeThreshold, kEdgeThreshold, kEdgeThreshold,
                       cv::BORDER_REFLECT_101);
    pyramid_[l] = padded_[l](cv::Rect(kEdgeThreshold, kEdgeThreshold, sz.width, sz.height));
  }
}

std::vector<cv::KeyPoint> OrbExtractor::detect_level(int level, int num_wanted) const {
  const cv::Mat& img = pyramid_[level];
  const int min_x = kEdgeThreshold - kFastBorderPx, min_y = min_x;
  const int max_x = img.cols - kEdgeThreshold + kFastBorderPx;
  const int max_y = img.rows - kEdgeThreshold + kFastBorderPx;
  const int width = max_x - min_x, height = max_y - min_y;
  if (width <= 2 * kFastBorderPx || height <= 2 * kFastBorderPx) return {};
  const int num_cols = std::max(1, width / kCellSizePx);
  const int num_rows = std::max(1, height / kCellSizePx);
  const int w_cell = (width + num_cols - 1) / num_cols;
  const int h_cell = (height + num_rows - 1) / num_rows;

  // FAST once over the whole detection area at the initial threshold, then
  // per cell: its corners, or, where it has none, FAST on the cell alone at
  // the minimum threshold (ORB-SLAM2's per-cell fallback).  ORB-SLAM2 runs
  // FAST on every 30 px cell (plus a 3 px margin) separately; one call per
  // level gives the same corners and scores in the cell interiors, and
  // non-maximum suppression that also sees across cell borders (see
  // docs/slam.md, "Deviations").
  const cv::Mat area = img(cv::Range(min_y, max_y), cv::Range(min_x, max_x));
  std::vector<cv::KeyPoint> strong;
  strong.reserve(static_cast<size_t>(num_wanted) * 10);
  cv::FAST(area, strong, params_.ini_fast_threshold, true);
  // Cell (i, j) detects in [min + kFastBorderPx + i * h_cell, ... + h_cell):
  // bucket the corners (area coordinates) by that rule.
  std::vector<std::vector<cv::KeyPoint>> per_cell(static_cast<size_t>(num_rows) * num_cols);
  for (const cv::KeyPoint& kp : strong) {
    const int j = std::min(num_cols - 1, (static_cast<int>(kp.pt.x) - kFastBorderPx) / w_cell);
    const int i = std::min(num_rows - 1, (static_cast<int>(kp.pt.y) - kFastBorderPx) / h_cell);
    per_cell[static_cast<size_t>(i) * num_cols + j].push_back(kp);
  }

  std::vector<cv::KeyPoint> all, cell;
  all.reserve(strong.size() + 64);
  for (int i = 0; i < num_rows; ++i) {
    const int y0 = min_y + i * h_cell;
    int y1 = y0 + h_cell + 2 * kFastBorderPx;
    if (y0 >= max_y - kFastBorderPx) continue;
    y1 = std::min(y1, max_y);
    for (int j = 0; j < num_cols; ++j) {
      const int x0 = min_x + j * w_cell;
      int x1 = x0 + w_cell + 2 * kFastBorderPx;
      if (x0 >= max_x - kFastBorderPx) continue;
      x1 = std::min(x1, max_x);
      const std::vector<cv::KeyPoint>& found = per_cell[static_cast<size_t>(i) * num_cols + j];
      if (!found.empty()) {
        for (cv::KeyPoint kp : found) {
          kp.pt.x += static_cast<float>(min_x);
          kp.pt.y += static_cast<float>(min_y);
          all.push_back(kp);
        }
        continue;
      }
      const cv::Mat roi = img(cv::Range(y0, y1), cv::Range(x0, x1));
      cell.clear();
      cv::FAST(roi, cell, params_.min_fast_threshold, true);
      for (auto& kp : cell) {
        kp.pt.x += static_cast<float>(x0);
        kp.pt.y += static_cast<float>(y0);
        all.push_back(kp);
      }
    }
  }
  std::vector<cv::KeyPoint> kept = distribute_quadtree(all, static_cast<float>(min_x), static_cast<float>(max_x),
                                                       static_cast<float>(min_y), static_cast<float>(max_y), num_wanted);
  const float size = static_cast<float>(kPatchSize * scales_[level]);
  for (auto& kp : kept) {
    kp.octave = level;
    kp.size = size;
    kp.angle = ic_angle_deg(img, kp.pt, umax_);
  }
  return kept;
}

OrbFeatures OrbExtractor::extract(const cv::Mat& image) {
  build_pyramid(grey_image(image));

  OrbFeatures out;
  std::vector<std::vector<cv::KeyPoint>> per_level(params_.num_levels);
  int total = 0;
  for (int l = 0; l < params_.num_levels; ++l) {
    per_level[l] = detect_level(l, features_per_level_[l]);
    total += static_cast<int>(per_level[l].size());
  }
  // The quadtree may return a few more nodes than asked; ORB-SLAM2 keeps them
  // all, we cap at num_features by dropping the weakest of the excess.
  out.keypoints.reserve(total);
  out.descriptors.create(total, 32, CV_8U);
  int row = 0;
  cv::Mat blurred;
  for (int l = 0; l < params_.num_levels; ++l) {
    if (per_level[l].empty()) continue;
    cv::GaussianBlur(padded_[l], blurred, cv::Size(7, 7), 2, 2, cv::BORDER_REFLECT_101);
    const cv::Mat view = blurred(cv::Rect(kEdgeThreshold, kEdgeThreshold, pyramid_[l].cols, pyramid_[l].rows));
    // Level pixel centres back to level-0 pixels. cv::resize (INTER_LINEAR)
    // maps a destination pixel x to source (x + 0.5) * ratio - 0.5, and the
    // ratios compose, so level l's pixel x sits at (x + 0.5) * W0 / Wl - 0.5.
    // ORB-SLAM2 multiplies by the nominal scale instead, which puts level-l
    // keypoints 0.5 * (scale - 1) px too far up and left (1.3 px at level 7).
    const float sx = static_cast<float>(pyramid_[0].cols) / static_cast<float>(pyramid_[l].cols);
    const float sy = static_cast<float>(pyramid_[0].rows) / static_cast<float>(pyramid_[l].rows);
    const cv::Mat& level = pyramid_[l];
    for (cv::KeyPoint kp : per_level[l]) {
      compute_rbrief(view, kp, out.descriptors.ptr<uchar>(row++));
      if (params_.sub_pixel) {
        const cv::Point2f off = sub_pixel_offset(level, kp);
        kp.pt.x += off.x;
        kp.pt.y += off.y;
      }
      kp.pt.x = (kp.pt.x + 0.5f) * sx - 0.5f;
      kp.pt.y = (kp.pt.y + 0.5f) * sy - 0.5f;
      out.keypoints.push_back(kp);
    }
  }
  if (total > params_.num_features) return strongest(out, params_.num_features);
  return out;
}

}  // namespace pvb::slam
