#include "pvb/sim/textures.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

namespace pvb::sim {
namespace {

// Small deterministic helpers (std distributions are implementation-defined;
// these keep textures identical across standard libraries).
struct Rng {
  explicit Rng(std::uint64_t seed) : gen(seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull) {}
  double uniform() { return static_cast<double>(gen() >> 11) * (1.0 / 9007199254740992.0); }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int integer(int a, int b) { return a + static_cast<int>(uniform() * (b - a + 1)) % (b - a + 1); }
  double normal() {  // Box-Muller
    const double u1 = std::max(uniform(), 1e-300), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  std::mt19937_64 gen;
};

cv::Scalar rgb(double r, double g, double b) { return cv::Scalar(r, g, b); }

// Adds zero-mean per-pixel noise of the given amplitude.
void add_noise(cv::Mat* img, Rng* rng, double amplitude) {
  for (int r = 0; r < img->rows; ++r) {
    auto* p = img->ptr<cv::Vec3b>(r);
    for (int c = 0; c < img->cols; ++c) {
      const double n = rng->normal() * amplitude;
      for (int k = 0; k < 3; ++k) p[c][k] = cv::saturate_cast<uchar>(p[c][k] + n);
    }
  }
}

// Smooth value noise in [0, 1] at a given cell size, tiled seamlessly.
cv::Mat value_noise(int size, int cells, Rng* rng) {
  cv::Mat grid(cells, cells, CV_32F);
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) grid.at<float>(r, c) = static_cast<float>(rng->uniform());
  cv::Mat out(size, size, CV_32F);
  const double step = static_cast<double>(size) / cells;
  for (int r = 0; r < size; ++r) {
    const double fy = r / step;
    const int y0 = static_cast<int>(fy) % cells, y1 = (y0 + 1) % cells;
    double ty = fy - std::floor(fy);
    ty = ty * ty * (3 - 2 * ty);
    for (int c = 0; c < size; ++c) {
      const double fx = c / step;
      const int x0 = static_cast<int>(fx) % cells, x1 = (x0 + 1) % cells;
      double tx = fx - std::floor(fx);
      tx = tx * tx * (3 - 2 * tx);
      const double a = grid.at<float>(y0, x0) * (1 - tx) + grid.at<float>(y0, x1) * tx;
      const double b = grid.at<float>(y1, x0) * (1 - tx) + grid.at<float>(y1, x1) * tx;
      out.at<float>(r, c) = static_cast<float>(a * (1 - ty) + b * ty);
    }
  }
  return out;
}

}  // namespace

cv::Mat make_panel_texture(const scenes::PvArray& array, double dirt, std::uint64_t station_seed,
                           std::uint64_t day_seed) {
  Rng rng(station_seed);
  // Cell grid: 60 -> 6x10, 72 -> 6x12, 144 half-cut -> 6x24 (cells are half height).
  const int cols = 6;
  const int rows = array.cells == 60 ? 10 : array.cells == 72 ? 12 : 24;
  const bool portrait = array.orientation == scenes::PanelOrientation::kPortrait;
  const int cell_px = 26;
  const int cell_h_px = array.cells == 144 ? cell_px / 2 : cell_px;
  const int gap_px = 2, frame_px = 5;
  const int w = frame_px * 2 + cols * cell_px + (cols - 1) * gap_px;
  const int h = frame_px * 2 + rows * cell_h_px + (rows - 1) * gap_px + (array.cells == 144 ? 6 : 0);
  // Backsheet (white-ish) visible between cells.
  cv::Mat img(h, w, CV_8UC3, rgb(196, 200, 206));
  const int busbars = 5;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const int x = frame_px + c * (cell_px + gap_px);
      int y = frame_px + r * (cell_h_px + gap_px);
      if (array.cells == 144 && r >= rows / 2) y += 6;  // junction gap of half-cut modules
      const double shade = rng.uniform(-6, 6);
      cv::rectangle(img, cv::Rect(x, y, cell_px, cell_h_px), rgb(22 + shade, 34 + shade, 70 + shade * 1.5), cv::FILLED);
      // chamfered corners of mono cells
      for (int k = 0; k < 3; ++k) {
        cv::line(img, {x, y + k}, {x + 2 - k, y}, rgb(196, 200, 206));
        cv::line(img, {x + cell_px - 1, y + k}, {x + cell_px - 3 + k, y}, rgb(196, 200, 206));
      }
      for (int b = 1; b <= busbars; ++b) {
        const int bx = x + b * cell_px / (busbars + 1);
        cv::line(img, {bx, y}, {bx, y + cell_h_px - 1}, rgb(150, 155, 165));
      }
    }
  }
  add_noise(&img, &rng, 3.0);
  // The dust is the day's: drawn from the day's seed, on its stream where
  // the cells above leave off (one number per cell, two per pixel of noise),
  // so that with the station's seed it is the one stream it always was.
  rng = Rng(day_seed);
  rng.gen.discard(static_cast<unsigned long long>(rows) * cols + 2ULL * static_cast<unsigned long long>(w) * h);
  // Dust: low-frequency mask, stronger towards the lower edge where rain
  // leaves it; then a few stains (bird droppings, water marks).
  if (dirt > 0) {
    const int n = std::max(w, h);
    cv::Mat noise = value_noise(n, 8, &rng);
    cv::Mat fine = value_noise(n, 40, &rng);
    for (int r = 0; r < h; ++r) {
      const double edge = std::pow(static_cast<double>(r) / h, 3.0);  // lower edge = last rows
      auto* p = img.ptr<cv::Vec3b>(r);
      for (int c = 0; c < w; ++c) {
        double a = dirt * (0.55 * noise.at<float>(r, c) + 0.25 * fine.at<float>(r, c) + 0.6 * edge) - 0.15;
        a = std::clamp(a, 0.0, 0.85);
        const cv::Vec3d dust(150, 128, 98);
        for (int k = 0; k < 3; ++k) p[c][k] = cv::saturate_cast<uchar>(p[c][k] * (1 - a) + dust[k] * a);
      }
    }
    const int stains = static_cast<int>(std::round(dirt * 8));
    for (int i = 0; i < stains; ++i) {
      const int y = rng.integer(frame_px, h - frame_px), x = rng.integer(frame_px, w - frame_px);
      const cv::Point ctr(x, y);
      const int rad = rng.integer(2, 6);
      cv::circle(img, ctr, rad, rgb(225, 222, 210), cv::FILLED, cv::LINE_AA);
      for (int k = 0; k < 4; ++k) {
        const int r = rng.integer(1, 2), dy = rng.integer(-8, 8), dx = rng.integer(-8, 8);
        cv::circle(img, ctr + cv::Point(dx, dy), r, rgb(215, 212, 200), cv::FILLED, cv::LINE_AA);
      }
    }
  }
  // Aluminium frame last, so dirt never covers its silhouette.
  cv::rectangle(img, cv::Rect(0, 0, w, h), rgb(176, 180, 184), frame_px * 2);
  cv::rectangle(img, cv::Rect(frame_px - 1, frame_px - 1, w - 2 * frame_px + 2, h - 2 * frame_px + 2),
                rgb(120, 124, 128), 1);
  if (!portrait) {
    cv::Mat rotated;
    cv::rotate(img, rotated, cv::ROTATE_90_CLOCKWISE);
    return rotated;
  }
  return img;
}

cv::Mat make_brick_texture(std::uint64_t seed) {
  Rng rng(seed ^ 0xB51C);
  const int w = 512;
  const int h = static_cast<int>(std::lround(w * kBrickTileHeightM / kBrickTileWidthM));
  cv::Mat img(h, w, CV_8UC3, rgb(168, 166, 160));  // mortar
  const int courses = 10, per_course = 4;
  const double course_h = static_cast<double>(h) / courses, brick_w = static_cast<double>(w) / per_course;
  const double joint = 0.010 / (kBrickTileWidthM / w);
  for (int r = 0; r < courses; ++r) {
    const double off = (r % 2) * 0.5 * brick_w;
    for (int b = -1; b <= per_course; ++b) {
      const double x0 = b * brick_w + off + joint / 2, x1 = (b + 1) * brick_w + off - joint / 2;
      const double y0 = r * course_h + joint / 2, y1 = (r + 1) * course_h - joint / 2;
      const double g = 112 + rng.uniform(-7, 7);  // grey, of high similarity
      cv::rectangle(img, cv::Point(static_cast<int>(x0), static_cast<int>(y0)),
                    cv::Point(static_cast<int>(x1), static_cast<int>(y1)), rgb(g, g - 1, g - 3), cv::FILLED);
    }
  }
  add_noise(&img, &rng, 6.0);
  return img;
}

int unique_ground_slots(double within_m) {
  if (within_m <= 0) return 0;
  // A tile is near when its centre lies within r = within_m + h (h: half the
  // diagonal); the 3 m cells of those centres lie in the disc of r + h.
  const double h = kGroundTileM / std::sqrt(2.0), r = within_m + 2 * h;
  return static_cast<int>(std::ceil(M_PI * r * r / (kGroundTileM * kGroundTileM)));
}

cv::Mat make_ground_texture(scenes::GroundType type, std::uint64_t seed) {
  Rng rng(seed ^ 0x50C1);
  const int n = kGroundTexturePx;
  cv::Mat low = value_noise(n, 6, &rng), mid = value_noise(n, 24, &rng);
  const bool gravel = type == scenes::GroundType::kGravel;
  const cv::Vec3d base = gravel ? cv::Vec3d(128, 124, 118) : cv::Vec3d(112, 88, 62);
  cv::Mat img(n, n, CV_8UC3);
  for (int r = 0; r < n; ++r) {
    auto* p = img.ptr<cv::Vec3b>(r);
    for (int c = 0; c < n; ++c) {
      const double s = 0.75 + 0.35 * low.at<float>(r, c) + 0.2 * mid.at<float>(r, c);
      for (int k = 0; k < 3; ++k) p[c][k] = cv::saturate_cast<uchar>(base[k] * s);
    }
  }
  // Stones and pebbles: what gives the ground texture for tracking.
  const int stones = gravel ? 2600 : 700;
  for (int i = 0; i < stones; ++i) {
    const int y = rng.integer(0, n - 1), x = rng.integer(0, n - 1);
    const int ax_h = rng.integer(1, gravel ? 5 : 3), ax_w = rng.integer(1, gravel ? 6 : 4);
    const double g = gravel ? rng.uniform(90, 200) : rng.uniform(60, 170);
    const cv::Scalar col = gravel ? rgb(g, g * 0.97, g * 0.92) : rgb(g, g * 0.86, g * 0.68);
    const double angle_deg = rng.uniform(0, 180);
    cv::ellipse(img, {x, y}, {ax_w, ax_h}, angle_deg, 0, 360, col, cv::FILLED, cv::LINE_AA);
  }
  if (!gravel) {  // dry grass tufts
    for (int i = 0; i < 250; ++i) {
      const int ay = rng.integer(0, n - 1), ax = rng.integer(0, n - 1);
      const int dy = rng.integer(-9, -2), dx = rng.integer(-6, 6);
      const double green = rng.uniform(120, 140), red = rng.uniform(120, 160);
      cv::line(img, {ax, ay}, {ax + dx, ay + dy}, rgb(red, green, 60), 1, cv::LINE_AA);
    }
  }
  add_noise(&img, &rng, 5.0);
  return img;
}

cv::Mat make_sign_atlas(const std::vector<std::string>& labels) {
  const int lines = std::max(1, (static_cast<int>(labels.size()) + kSignAtlasColumns - 1) / kSignAtlasColumns);
  cv::Mat img(lines * kSignCellHeightPx, kSignAtlasColumns * kSignCellWidthPx, CV_8UC3, rgb(236, 236, 230));
  const cv::Scalar ink = rgb(20, 22, 26);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const cv::Point corner(static_cast<int>(i % kSignAtlasColumns) * kSignCellWidthPx,
                           static_cast<int>(i / kSignAtlasColumns) * kSignCellHeightPx);
    cv::rectangle(img, cv::Rect(corner, cv::Size(kSignCellWidthPx, kSignCellHeightPx)), ink, 4);
    const std::size_t space = labels[i].find(' ');
    const std::string words[2] = {space == std::string::npos ? "" : labels[i].substr(0, space),
                                  space == std::string::npos ? labels[i] : labels[i].substr(space + 1)};
    const double scale[2] = {0.8, 1.25};
    const int thick[2] = {2, 3}, baseline[2] = {32, 80};
    for (int w = 0; w < 2; ++w) {
      int base = 0;
      const cv::Size size = cv::getTextSize(words[w], cv::FONT_HERSHEY_SIMPLEX, scale[w], thick[w], &base);
      cv::putText(img, words[w], corner + cv::Point((kSignCellWidthPx - size.width) / 2, baseline[w]),
                  cv::FONT_HERSHEY_SIMPLEX, scale[w], ink, thick[w], cv::LINE_AA);
    }
  }
  return img;
}

cv::Mat make_track_texture(std::uint64_t seed) {
  Rng rng(seed ^ 0x7AC4);
  const int n = 256;
  cv::Mat img(n, n, CV_8UC3);
  const cv::Mat low = value_noise(n, 4, &rng);
  for (int r = 0; r < n; ++r) {
    auto* p = img.ptr<cv::Vec3b>(r);
    for (int c = 0; c < n; ++c) {
      const double s = 0.52 + 0.16 * low.at<float>(r, c);
      p[c] = cv::Vec3b(cv::saturate_cast<uchar>(112 * s), cv::saturate_cast<uchar>(88 * s), cv::saturate_cast<uchar>(62 * s));
    }
  }
  // The tread: a bar across the track every 8 cm (41 px), each a little
  // skewed and broken where the soil did not take it.
  for (int x = 0; x < n; x += 41) {
    const int skew = rng.integer(-6, 6), width = rng.integer(8, 12);
    for (int y = 0; y < n; y += 16)
      if (rng.uniform(0, 1) > 0.15)
        cv::line(img, {x + skew * y / n, y}, {x + skew * (y + 16) / n, y + 16}, rgb(52, 40, 30), width, cv::LINE_AA);
  }
  for (int i = 0; i < 120; ++i) {  // crushed stones
    const int y = rng.integer(0, n - 1), x = rng.integer(0, n - 1);
    const double g = rng.uniform(70, 150);
    cv::circle(img, {x, y}, rng.integer(1, 2), rgb(g, g * 0.86, g * 0.7), cv::FILLED, cv::LINE_AA);
  }
  add_noise(&img, &rng, 5.0);
  return img;
}

cv::Mat make_grass_texture(std::uint64_t seed) {
  Rng rng(seed ^ 0x6A55);
  const int n = 256;
  cv::Mat img(n, n, CV_8UC3, rgb(96, 78, 54));
  for (int i = 0; i < 1800; ++i) {  // blades: short strokes, green to straw
    const int y = rng.integer(0, n - 1), x = rng.integer(0, n - 1);
    const int dx = rng.integer(-5, 5), dy = rng.integer(-12, -3);
    const double dry = rng.uniform(0, 1), g = rng.uniform(90, 160);
    cv::line(img, {x, y}, {x + dx, y + dy}, rgb(g * (0.55 + 0.5 * dry), g, g * (0.3 + 0.2 * dry)), 1, cv::LINE_AA);
  }
  add_noise(&img, &rng, 6.0);
  return img;
}

cv::Mat make_foliage_texture(std::uint64_t seed) {
  Rng rng(seed ^ 0xF011);
  const int n = 256;
  cv::Mat img(n, n, CV_8UC3, rgb(40, 70, 30));
  for (int i = 0; i < 1400; ++i) {
    const int y = rng.integer(0, n - 1), x = rng.integer(0, n - 1);
    const double g = rng.uniform(60, 140);
    const double angle_deg = rng.uniform(0, 180);
    const int ax_h = rng.integer(1, 3), ax_w = rng.integer(2, 5);
    cv::ellipse(img, {x, y}, {ax_w, ax_h}, angle_deg, 0, 360, rgb(g * 0.55, g, g * 0.35), cv::FILLED, cv::LINE_AA);
  }
  add_noise(&img, &rng, 6.0);
  return img;
}

cv::Mat make_bark_texture(std::uint64_t seed) {
  Rng rng(seed ^ 0xBA4C);
  const int n = 128;
  cv::Mat img(n, n, CV_8UC3, rgb(90, 70, 52));
  for (int i = 0; i < 60; ++i) {
    const int x = rng.integer(0, n - 1);
    const int thickness = rng.integer(1, 2), dx = rng.integer(-4, 4);
    cv::line(img, {x, 0}, {x + dx, n - 1}, rgb(60, 46, 34), thickness, cv::LINE_AA);
  }
  add_noise(&img, &rng, 8.0);
  return img;
}

}  // namespace pvb::sim
