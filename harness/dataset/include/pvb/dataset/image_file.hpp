#pragma once
// Image files read with one clear error.  OpenCV's decoders report a damaged
// file on stderr themselves (libpng prints "libpng error: ...", imread prints
// "can't read data" for a short PNM) before imread returns an empty image;
// here a PNG's chunk structure (every CRC, the IEND chunk) and a PNM's header
// and payload size are checked before anything is decoded, so that a
// truncated or corrupt file is one pvb::IoError naming it.
#include <opencv2/core.hpp>
#include <optional>
#include <string>

namespace pvb::dataset {

/// Why the bytes of a PNG or PNM file cannot be a whole image ("truncated
/// PNG: ends inside chunk IDAT, before IEND"), or nullopt when they can or
/// the bytes are in another format (which is then left to the decoder).
std::optional<std::string> image_damage(const std::string& bytes);

/// Reads an image as cv::imread(path, imread_flags) does.  `what` names the
/// image in messages ("colour image").  Throws pvb::IoError naming `path`:
/// "missing or unreadable WHAT" when the file cannot be read or decoded,
/// "damaged WHAT: REASON" when image_damage() finds a reason.
cv::Mat read_image(const std::string& path, int imread_flags, const std::string& what = "image");

}  // namespace pvb::dataset
