#include "pvb/plot/contact_sheet.hpp"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pvb/common/error.hpp"
#include "pvb/plot/png.hpp"

namespace pvb::plot {

cv::Mat make_contact_sheet(const std::vector<Thumbnail>& thumbs, int cols, int thumb_width) {
  if (thumbs.empty()) return cv::Mat(1, 1, CV_8UC3, cv::Scalar(255, 255, 255));
  const double aspect = static_cast<double>(thumbs[0].rgb.rows) / thumbs[0].rgb.cols;
  const int th = static_cast<int>(std::lround(thumb_width * aspect));
  const int gap = 6;
  const int n = static_cast<int>(thumbs.size());
  cols = std::max(1, std::min(cols, n));
  const int rows = (n + cols - 1) / cols;
  cv::Mat sheet(gap + rows * (th + gap), gap + cols * (thumb_width + gap), CV_8UC3, cv::Scalar(250, 250, 250));
  for (int i = 0; i < n; ++i) {
    const cv::Rect cell(gap + (i % cols) * (thumb_width + gap), gap + (i / cols) * (th + gap), thumb_width, th);
    cv::Mat small;
    cv::resize(thumbs[static_cast<std::size_t>(i)].rgb, small, cell.size(), 0, 0, cv::INTER_AREA);
    small.copyTo(sheet(cell));
    const std::string& label = thumbs[static_cast<std::size_t>(i)].label;
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &base);
    cv::rectangle(sheet, cv::Rect(cell.x, cell.y, ts.width + 8, ts.height + base + 6), cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(sheet, label, {cell.x + 4, cell.y + ts.height + 3}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return sheet;
}

void write_rgb_png(const cv::Mat& rgb, const std::string& path) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  write_image(bgr, path);
}

std::vector<int> spread_indices(int n, int count) {
  std::vector<int> out;
  if (n <= 0 || count <= 0) return out;
  if (count == 1 || n == 1) return {0};
  count = std::min(count, n);
  for (int k = 0; k < count; ++k) out.push_back(static_cast<int>(std::lround(k * (n - 1.0) / (count - 1.0))));
  return out;
}

}  // namespace pvb::plot
