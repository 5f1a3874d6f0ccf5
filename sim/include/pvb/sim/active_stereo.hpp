#pragma once
// An active stereo depth camera (RealSense D435, scenes::ActiveStereo): two
// infrared imagers see the scene's own light plus a projected dot pattern,
// OpenCV's semi-global matcher finds the disparity, and the depth is
// registered to the colour camera beside them (docs/sensors.md, "Active
// stereo").  Every random draw comes from a generator seeded by (scenario
// seed, frame index, row), as in the Kinect model.
#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/glass.hpp"

namespace pvb::sim {

/// One infrared imager's view as rendered.
struct InfraredView {
  cv::Mat grey;     ///< CV_8UC1: the rendered scene's luma (its sun, sky and shadows)
  cv::Mat depth_m;  ///< CV_32FC1: exact depth along the optical axis, 0 = sky
  cv::Mat lit;      ///< CV_8UC1: 1 where the sun reaches the point seen (sun_visibility); empty: nowhere
  GlassView glass;  ///< specular panels' glass (face empty: none)
};

/// Both imagers' views of one frame.  The imagers and the colour camera
/// share one orientation; they sit along its x axis.
struct StereoRender {
  InfraredView left, right;
  Eigen::Vector3f to_sun_c = Eigen::Vector3f::UnitZ();  ///< unit, camera frame
};

/// Where one frame's depth time went.
struct StereoTimes {
  double images_ms = 0;    ///< the two infrared images (pattern, exposure, noise)
  double match_ms = 0;     ///< semi-global matching
  double register_ms = 0;  ///< disparity to depth in the colour camera
};

/// The projector's spots as relative irradiance over its field (mean 1):
/// `dots` Gaussian spots at seeded uniform positions, each 0.7 infrared
/// pixels wide (one sigma), on a grid of half an infrared pixel.
class DotPattern {
 public:
  explicit DotPattern(const scenes::ActiveStereo& p);
  /// At direction (tx, ty) = (x / z, y / z) in the projector's frame
  /// (bilinear); 0 outside its field or without spots.
  float at(float tx, float ty) const;
  /// The brightest spot's value (the mean is 1).
  float peak() const { return peak_; }

 private:
  cv::Mat tex_;  ///< CV_32FC1
  float half_w_ = 0, half_h_ = 0;  ///< the field's half width and height, tan units
  float texels_per_unit_ = 1;
  float peak_ = 0;
};

/// The d435 model of a scenario's camera.  const and stateless: safe on
/// any thread.
class ActiveStereoModel {
 public:
  ActiveStereoModel(const scenes::Camera& cam, double sun_elevation_deg, std::uint64_t seed);
  const geom::PinholeIntrinsics& ir_intrinsics() const { return K_ir_; }
  /// The range beyond which even the brightest spot adds less than 0.5 %
  /// to a shaded surface: where sun_visibility need not look.
  float pattern_range_m() const;
  /// One imager's 8-bit image: the rendered luma times (1 + projector
  /// irradiance / ambient irradiance), on specular glass (1 - R) of that
  /// plus what the glass mirrors (apply_glass), automatic exposure to
  /// middle grey over the central region, Gaussian read noise.
  cv::Mat infrared_image(const InfraredView& view, bool right_imager, const Eigen::Vector3f& to_sun_c,
                         std::uint64_t frame) const;
  /// The left image's disparity (CV_32FC1, pixels; 0 where the matcher found none).
  cv::Mat disparity(const cv::Mat& left, const cv::Mat& right) const;
  /// Depth in the colour camera (CV_32FC1, metres, 0 = none), cut to the
  /// depth range and on the 16-bit grid of TUM PNGs.
  cv::Mat depth(const StereoRender& views, std::uint64_t frame, StereoTimes* times = nullptr) const;

 private:
  scenes::Camera cam_;
  geom::PinholeIntrinsics K_ir_, K_colour_;
  float beam_w_m2_ = 0, sky_w_m2_ = 0, intensity_w_sr_ = 0;
  std::uint64_t seed_ = 0;
  DotPattern dots_;
};

/// Source depth (CV_32FC1, 0 = none) as the destination camera sees it.
/// The cameras share one orientation; p_dst_src is the source camera's
/// centre in the destination's frame.  Each source pixel fills the
/// footprint of its square in the destination, widened by half a
/// destination pixel on each side; the nearest surface wins.
cv::Mat register_depth(const cv::Mat& depth_src, const geom::PinholeIntrinsics& K_src,
                       const Eigen::Vector3d& p_dst_src, const geom::PinholeIntrinsics& K_dst);

}  // namespace pvb::sim
