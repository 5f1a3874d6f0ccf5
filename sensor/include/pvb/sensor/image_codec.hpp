#pragma once
// OpenCV's image codecs behind a plug-in module (libpvb_imgcodecs.so),
// loaded by the first call.  libopencv_imgcodecs brings about 140 shared
// libraries (GDAL, GDCM, OpenEXR and theirs) that cost a process about
// 0.12 s to load at its start, whether it ever reads an image or not; a
// pvbench that refuses its input, or a run that writes no image, no longer
// pays it.  Each function is OpenCV's of the same name, done by OpenCV: the
// same bytes, the same flags and parameters (<opencv2/imgcodecs.hpp>), the
// same cv::Exception on a bad argument.  A module that cannot be loaded
// throws pvb::UnavailableError.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace pvb::sensor {

bool imencode(const std::string& ext, const cv::Mat& image, std::vector<unsigned char>* bytes,
              const std::vector<int>& params = {});
cv::Mat imdecode(const cv::Mat& buffer, int flags);
cv::Mat imread(const std::string& path, int flags);
bool imwrite(const std::string& path, const cv::Mat& image, const std::vector<int>& params = {});

}  // namespace pvb::sensor
