#include "pvb/plot/png.hpp"

#include <cctype>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pvb/common/error.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/sensor/image_codec.hpp"

namespace pvb::plot {
namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// Hershey simplex at scale 1 has a cap height of about 22 px; SVG font-size
// is the em size, whose cap height is about 0.7 of it.
double font_scale(double size_px) { return size_px * 0.7 / 22.0; }
cv::Scalar bgr(const eval::Rgb& c) { return {double(c.b), double(c.g), double(c.r)}; }
cv::Point pt(double x, double y) { return {static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y))}; }

void draw_text(cv::Mat& img, const eval::FigText& t) {
  const double scale = font_scale(t.size_px);
  const int thickness = 1;
  int baseline = 0;
  const cv::Size sz = cv::getTextSize(t.text, kFont, scale, thickness, &baseline);
  double shift = 0;
  if (t.anchor == eval::TextAnchor::kMiddle) shift = sz.width / 2.0;
  if (t.anchor == eval::TextAnchor::kEnd) shift = sz.width;
  if (!t.vertical) {
    cv::putText(img, t.text, pt(t.x - shift, t.y), kFont, scale, bgr(t.color), thickness, cv::LINE_AA);
    return;
  }
  // Draw horizontally on a patch, rotate it counter-clockwise, paste it.
  cv::Mat patch(sz.height + baseline + 4, sz.width + 4, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(patch, t.text, {2, sz.height + 2}, kFont, scale, bgr(t.color), thickness, cv::LINE_AA);
  cv::Mat rotated;
  cv::rotate(patch, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
  // Baseline ends up on the right side of the rotated patch, text reads upwards.
  const int x0 = static_cast<int>(std::lround(t.x - (sz.height + 2)));
  const int y0 = static_cast<int>(std::lround(t.y - (rotated.rows - shift)));
  const cv::Rect dst = cv::Rect(x0, y0, rotated.cols, rotated.rows) & cv::Rect(0, 0, img.cols, img.rows);
  if (dst.area() <= 0) return;
  const cv::Rect src(dst.x - x0, dst.y - y0, dst.width, dst.height);
  cv::Mat region = img(dst);
  cv::min(region, rotated(src), region);  // white background: keep the darker pixel
}
}  // namespace

void write_png(const eval::Figure& figure, const std::string& path) {
  cv::Mat img(figure.height_px, figure.width_px, CV_8UC3, cv::Scalar(255, 255, 255));
  for (const eval::FigLine& l : figure.lines)
    cv::line(img, pt(l.x0, l.y0), pt(l.x1, l.y1), bgr(l.color), std::max(1, static_cast<int>(std::lround(l.width_px))),
             cv::LINE_AA);
  for (const eval::FigPolyline& p : figure.polylines) {
    std::vector<cv::Point> pts;
    pts.reserve(p.points.size());
    for (const auto& [x, y] : p.points) pts.push_back(pt(x, y));
    cv::polylines(img, pts, false, bgr(p.color), std::max(1, static_cast<int>(std::lround(p.width_px))), cv::LINE_AA);
  }
  for (const eval::FigText& t : figure.texts) draw_text(img, t);
  write_image(img, path);
}

void write_image(const cv::Mat& image, const std::string& path) {
  static const char* const kExtensions[] = {".png", ".jpg", ".jpeg", ".bmp", ".ppm", ".pgm", ".tif", ".tiff"};
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of('/');
  std::string ext = dot != std::string::npos && (slash == std::string::npos || dot > slash) ? path.substr(dot) : "";
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  bool known = false;
  for (const char* k : kExtensions) known = known || ext == k;
  if (!known) {
    if (resolve_output_target(path).kind != OutputTarget::Kind::kStream)
      throw IoError(path, "cannot write an image without an image extension (.png, .jpg, .bmp, .ppm, .tif)");
    ext = ".png";
  }
  std::vector<unsigned char> bytes;
  bool ok = false;
  try {
    ok = sensor::imencode(ext, image, &bytes);
  } catch (const cv::Exception& e) {
    throw IoError(path, std::string("cannot encode the image: ") + e.what());
  }
  if (!ok) throw IoError(path, "cannot encode the image as " + ext);
  write_file_via_temp(path, [&](OutputFile& out) {
    out.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  });
}

}  // namespace pvb::plot
