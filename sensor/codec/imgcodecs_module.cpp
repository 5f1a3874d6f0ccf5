// The image-codecs plug-in module (pvb/sensor/image_codec.hpp): OpenCV's
// functions behind C entry points that the loader finds with dlsym.  They
// take the C++ objects by pointer; cv::Exception passes through them.
#include <opencv2/imgcodecs.hpp>

#include <string>
#include <vector>

extern "C" {

bool pvb_imencode(const std::string* ext, const cv::Mat* image, std::vector<unsigned char>* bytes,
                  const std::vector<int>* params) {
  return cv::imencode(*ext, *image, *bytes, *params);
}

void pvb_imdecode(const cv::Mat* buffer, int flags, cv::Mat* image) { *image = cv::imdecode(*buffer, flags); }

void pvb_imread(const std::string* path, int flags, cv::Mat* image) { *image = cv::imread(*path, flags); }

bool pvb_imwrite(const std::string* path, const cv::Mat* image, const std::vector<int>* params) {
  return cv::imwrite(*path, *image, *params);
}

}  // extern "C"
