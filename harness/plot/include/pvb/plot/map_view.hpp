#pragma once
// A top view of a dense map coloured by each point's error against the true
// surface: where a map is wrong, at a glance.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace pvb::plot {

struct MapViewOptions {
  double max_error_m = 0.05;  ///< the top of the colour scale; larger errors are clipped to it
  int max_side_px = 1200;     ///< the map's longer side, pixels
  double min_cell_m = 0.01;   ///< no finer than this per pixel
};

/// The x-y plane seen from above (+x right, +y up, equal axes): each pixel
/// shows the error of the highest point in it, on the turbo colour map
/// from 0 to max_error_m; empty pixels are white.  Below: a title and the
/// colour bar with its scale in millimetres.  Returns R, G, B (CV_8UC3).
/// Throws std::invalid_argument when the sizes of p_w and error_m differ.
cv::Mat make_map_error_top_view(const std::vector<Eigen::Vector3d>& p_w, const std::vector<double>& error_m,
                                const std::string& title, const MapViewOptions& options = {});

}  // namespace pvb::plot
