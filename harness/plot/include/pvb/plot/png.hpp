#pragma once
// Rasterises a pvb::eval::Figure to PNG with OpenCV (imgproc drawing,
// imgcodecs encoding).  Kept out of pvb::eval so that library stays Eigen-only.
#include <string>

#include "pvb/eval/plot.hpp"

namespace pvb::plot {

/// Draws `figure` and writes it as PNG to `path`; throws pvb::IoError when
/// the file cannot be written.
void write_png(const eval::Figure& figure, const std::string& path);

}  // namespace pvb::plot
