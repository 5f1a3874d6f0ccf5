#pragma once
// Rasterises a pvb::eval::Figure to PNG with OpenCV (imgproc drawing,
// imgcodecs encoding).  Kept out of pvb::eval so that library stays Eigen-only.
#include <opencv2/core.hpp>
#include <string>

#include "pvb/eval/charts.hpp"

namespace pvb::plot {

/// Draws `figure` and writes it as PNG to `path`; throws pvb::IoError when
/// the file cannot be written.
void write_png(const eval::Figure& figure, const std::string& path);

/// Encodes a BGR (or grey) image in the format its file name's extension
/// names (.png, .jpg, ...) and writes it whole as pvb::write_file does: a
/// regular file is replaced atomically, a device, FIFO or standard stream
/// is written through (as PNG when its name has no image extension).
/// Throws pvb::IoError naming `path`.
void write_image(const cv::Mat& image, const std::string& path);

}  // namespace pvb::plot
