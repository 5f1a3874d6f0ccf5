#include "pvb/plot/matrix.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pvb/common/text.hpp"
#include "pvb/plot/png.hpp"

namespace pvb::plot {
namespace {

constexpr int kCell = 90, kLeft = 150, kTop = 70, kRight = 20, kBottom = 50;

/// Red (0) to yellow (0.5) to green (1), as 0-255 RGB.
std::array<int, 3> share_colour(double v) {
  const double s = std::clamp(v, 0.0, 1.0);
  const int r = s < 0.5 ? 220 : static_cast<int>(220 * (1 - s) * 2);
  const int g = s < 0.5 ? static_cast<int>(200 * s * 2) : 200;
  return {r, g, 60};
}

std::string xml(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return out;
}

std::string cell_text(const std::optional<double>& v) { return v ? format_fixed(100 * *v, 0) + " %" : "-"; }

/// Wide enough for the cells and for the title (about 11 px a character).
int width_of(const MatrixFigure& m) {
  return std::max(kLeft + kCell * static_cast<int>(m.cols.size()) + kRight, 20 + 11 * static_cast<int>(m.title.size()));
}

std::string svg(const MatrixFigure& m) {
  const int w = width_of(m);
  const int h = kTop + kCell * static_cast<int>(m.rows.size()) + kBottom;
  std::string out = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(w) + "\" height=\"" +
                    std::to_string(h) + "\" font-family=\"sans-serif\" font-size=\"13\">\n";
  out += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  out += "<text x=\"10\" y=\"22\" font-size=\"15\">" + xml(m.title) + "</text>\n";
  out += "<text x=\"" + std::to_string(kLeft) + "\" y=\"45\">" + xml(m.col_label) + "</text>\n";
  out += "<text x=\"10\" y=\"" + std::to_string(h - 15) + "\">rows: " + xml(m.row_label) + "</text>\n";
  for (std::size_t c = 0; c < m.cols.size(); ++c)
    out += "<text x=\"" + std::to_string(kLeft + kCell * static_cast<int>(c) + 6) + "\" y=\"" +
           std::to_string(kTop - 6) + "\">" + xml(m.cols[c]) + "</text>\n";
  for (std::size_t r = 0; r < m.rows.size(); ++r) {
    const int y = kTop + kCell * static_cast<int>(r);
    out += "<text x=\"10\" y=\"" + std::to_string(y + kCell / 2) + "\">" + xml(m.rows[r]) + "</text>\n";
    for (std::size_t c = 0; c < m.cols.size(); ++c) {
      const auto& v = m.values[r][c];
      const auto rgb = v ? share_colour(*v) : std::array<int, 3>{225, 225, 225};
      const int x = kLeft + kCell * static_cast<int>(c);
      out += "<rect x=\"" + std::to_string(x) + "\" y=\"" + std::to_string(y) + "\" width=\"" +
             std::to_string(kCell - 2) + "\" height=\"" + std::to_string(kCell - 2) + "\" fill=\"rgb(" +
             std::to_string(rgb[0]) + "," + std::to_string(rgb[1]) + "," + std::to_string(rgb[2]) + ")\"/>\n";
      out += "<text x=\"" + std::to_string(x + kCell / 2) + "\" y=\"" + std::to_string(y + kCell / 2 + 4) +
             "\" text-anchor=\"middle\">" + cell_text(v) + "</text>\n";
    }
  }
  return out + "</svg>\n";
}

cv::Mat raster(const MatrixFigure& m) {
  const int w = width_of(m);
  const int h = kTop + kCell * static_cast<int>(m.rows.size()) + kBottom;
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto text = [&](const std::string& s, int x, int y, double scale) {
    cv::putText(img, s, {x, y}, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  };
  text(m.title, 10, 22, 0.55);
  text(m.col_label, kLeft, 45, 0.45);
  text("rows: " + m.row_label, 10, h - 15, 0.45);
  for (std::size_t c = 0; c < m.cols.size(); ++c) text(m.cols[c], kLeft + kCell * static_cast<int>(c) + 4, kTop - 6, 0.4);
  for (std::size_t r = 0; r < m.rows.size(); ++r) {
    const int y = kTop + kCell * static_cast<int>(r);
    text(m.rows[r], 10, y + kCell / 2, 0.45);
    for (std::size_t c = 0; c < m.cols.size(); ++c) {
      const auto& v = m.values[r][c];
      const auto rgb = v ? share_colour(*v) : std::array<int, 3>{225, 225, 225};
      const int x = kLeft + kCell * static_cast<int>(c);
      cv::rectangle(img, cv::Rect(x, y, kCell - 2, kCell - 2), cv::Scalar(rgb[2], rgb[1], rgb[0]), cv::FILLED);
      text(cell_text(v), x + kCell / 2 - 22, y + kCell / 2 + 5, 0.5);
    }
  }
  return img;
}

}  // namespace

void write_matrix(const MatrixFigure& m, const std::string& path_base) {
  write_file(path_base + ".svg", svg(m));
  write_image(raster(m), path_base + ".png");
}

}  // namespace pvb::plot
