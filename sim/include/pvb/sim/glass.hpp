#pragma once
// Specular module glass (scenes::PvArray::specular_glass): which pixels
// show a panel's front glass, what the glass mirrors there (the sky's
// gradient, the ground, the sun's glint) with Fresnel's angle dependence,
// and what the mirror does to structured-light depth (docs/sensors.md,
// "Glass").  The truth (depth, geoms, surface classes) is not touched.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "pvb/geometry/pinhole.hpp"
#include "pvb/geometry/se3.hpp"

namespace pvb::sim {

/// Glass of refractive index 1.5 (soda-lime, uncoated).
inline constexpr double kGlassIndex = 1.5;
/// The cells' reflectance under the glass in the near infrared (830-850 nm)
/// and the reflectance of a typical surface the mirror shows.
inline constexpr double kCellNirReflectance = 0.08;
inline constexpr double kMirroredSurfaceReflectance = 0.3;
/// A Kinect returns the pattern from a surface of reflectance 0.5 to its
/// rated 4 m; a darker surface of reflectance rho to 4 m sqrt(rho / 0.5).
inline constexpr double kPatternReferenceReflectance = 0.5;
inline constexpr double kPatternRatedRangeM = 4.0;

/// The range to which the cells under the glass return enough of a
/// Kinect's pattern at incidence cosine cos_i: the cells' reflectance
/// through the glass twice, rho_c (1 - R)^2, against the reference's.
double glass_pattern_range_m(double cos_i);
/// The glint's angular width (one sigma) around the sun's mirror direction.
inline constexpr double kGlintSigmaDeg = 1.0;

/// Fresnel's reflectance of one air-glass surface for unpolarised light
/// arriving at incidence cosine `cos_i` (the mean of the s and p terms).
double fresnel_reflectance(double cos_i, double index = kGlassIndex);
/// fresnel_reflectance for kGlassIndex from a table (within 2e-4): the
/// per-pixel paths' Fresnel.
float fresnel_glass(double cos_i);

/// The glass faces one camera sees in one state.
struct GlassView {
  cv::Mat face;  ///< CV_16UC1: 0 = no glass, k + 1 = a glass face of normal normals_c[k]
  std::vector<Eigen::Vector3f> normals_c;  ///< unit, camera frame, towards the camera
  /// CV_32FC1: where a Kinect would take the mirror's image for the
  /// surface (mirror_depth_wins), the distance from the glass along the
  /// mirrored ray to the first surface (one ray per block of 4 x 4
  /// pixels of a face); 0 elsewhere or where the ray meets nothing
  /// within 20 m.
  cv::Mat mirror_m;
  Eigen::Matrix3f R_w_c = Eigen::Matrix3f::Identity();  ///< the camera's orientation
};

/// Where the pattern's mirror image outshines the cells' own return: the
/// mirrored surface's R^2 rho_s against the cells' rho_c (1 - R)^2.
bool mirror_depth_wins(double cos_i);

/// The specular panels' glass faces: the +z face of every box whose
/// material is a panel's in an array with specular glass.
class GlassFinder {
 public:
  /// `specular_arrays[i]`: whether array i's glass is specular.
  GlassFinder(const mjModel* m, const std::vector<bool>& specular_arrays);
  bool empty() const { return panels_.empty(); }
  /// The glass in a depth image (CV_32FC1, metres, 0 = none) seen from
  /// T_w_c: pixels whose surface point lies on a glass face (within 5 mm
  /// plus 0.2 % of the depth), and with `mirror_rays` (what a Kinect's
  /// depth needs) for mirror_depth_wins pixels the mirrored ray cast
  /// against the scene (mirror_m stays 0 without).
  GlassView find(const mjData* d, const cv::Mat& depth_m, const geom::PinholeIntrinsics& K, const geom::SE3d& T_w_c,
                 bool mirror_rays) const;

 private:
  const mjModel* m_;
  std::vector<int> panels_;  ///< geom ids
};

/// What the glass mirrors along a reflected direction (world frame), in
/// linear [0, 1] RGB: the sky's gradient above the horizon, a sunlit
/// soil's colour below it.
Eigen::Vector3f mirrored_colour(const Eigen::Vector3f& dir_w);

/// Colour on glass: (1 - R) c + R mirrored, plus the sun's glint, a
/// Gaussian lobe of 1 degree around the sun's mirror direction that
/// saturates at its centre.  rgb is CV_8UC3 (R, G, B) or CV_8UC1 (grey).
void apply_glass(cv::Mat* image, const GlassView& glass, const geom::PinholeIntrinsics& K,
                 const Eigen::Vector3f& to_sun_c, bool sun_up);

}  // namespace pvb::sim
