#include "pvb/report/plan_view.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pvb/common/text.hpp"
#include "pvb/scenes/route.hpp"

namespace pvb::run {
namespace {

constexpr int kFooterPx = 44;

/// World metres to plan pixels: x right, y up.
struct PlanFrame {
  Eigen::Vector2d min_m, max_m;
  double px_per_m = 1;
  int width = 1, height = 1;
  cv::Point px(const Eigen::Vector2d& p) const {
    return {static_cast<int>(std::lround((p.x() - min_m.x()) * px_per_m)),
            static_cast<int>(std::lround((max_m.y() - p.y()) * px_per_m))};
  }
};

/// What the plan shows: the plant with 10 m around it when it has one, else the ground.
PlanFrame frame_for(const scenes::Scenario& s, int max_side_px) {
  PlanFrame f;
  f.min_m = -0.5 * s.ground.size_m;
  f.max_m = 0.5 * s.ground.size_m;
  if (s.plant) {
    const std::vector<Eigen::Vector2d>& corners = s.plant->fence ? s.plant->fence->corners_m : s.plant->corners_m;
    Eigen::Vector2d lo = corners[0], hi = lo;
    for (const Eigen::Vector2d& c : corners) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    f.min_m = (lo - Eigen::Vector2d::Constant(10)).cwiseMax(f.min_m);
    f.max_m = (hi + Eigen::Vector2d::Constant(10)).cwiseMin(f.max_m);
  }
  const Eigen::Vector2d size = f.max_m - f.min_m;
  f.px_per_m = max_side_px / size.maxCoeff();
  f.width = std::max(1, static_cast<int>(std::lround(size.x() * f.px_per_m)));
  f.height = std::max(1, static_cast<int>(std::lround(size.y() * f.px_per_m)));
  return f;
}

void fill_quad(cv::Mat& img, const PlanFrame& f, const std::vector<Eigen::Vector2d>& corners, const cv::Vec3b& rgb) {
  std::vector<cv::Point> pts;
  for (const Eigen::Vector2d& c : corners) pts.push_back(f.px(c));
  cv::fillConvexPoly(img, pts, cv::Scalar(rgb[0], rgb[1], rgb[2]), cv::LINE_8);
}

void draw_arrays(cv::Mat& img, const PlanFrame& f, const scenes::Scenario& s) {
  for (const scenes::PvArray& a : s.pv_arrays) {
    const double tl = a.table_length_m(), depth = scenes::row_footprint_m(a);
    for (int row = 0; row < a.rows; ++row)
      for (int t = 0; t < a.tables_per_row; ++t) {
        const double u0 = t * (tl + a.table_gap_m), v0 = row * a.row_pitch_m;
        fill_quad(img, f,
                  {scenes::array_to_world(a, u0, v0), scenes::array_to_world(a, u0 + tl, v0),
                   scenes::array_to_world(a, u0 + tl, v0 + depth), scenes::array_to_world(a, u0, v0 + depth)},
                  kPlanTableRgb);
      }
  }
}

void draw_walls(cv::Mat& img, const PlanFrame& f, const scenes::Scenario& s) {
  for (const scenes::Wall& w : s.walls) {
    const Eigen::Vector2d along = (w.end_m - w.start_m).normalized();
    const Eigen::Vector2d side = Eigen::Vector2d(-along.y(), along.x()) * std::max(w.thickness_m / 2, 0.5 / f.px_per_m);
    const cv::Vec3b rgb = w.finish == scenes::WallFinish::kPlaster ? cv::Vec3b(200, 195, 185) : cv::Vec3b(150, 70, 50);
    fill_quad(img, f, {w.start_m - side, w.end_m - side, w.end_m + side, w.start_m + side}, rgb);
  }
}

/// The plant's roads (gravel), fence (a line, gates left open), dock and combiner boxes.
void draw_plant(cv::Mat& img, const PlanFrame& f, const scenes::Scenario& s) {
  if (!s.plant) return;
  const scenes::PlantSummary& plant = *s.plant;
  const scenes::PvArray& base = s.pv_arrays[static_cast<std::size_t>(plant.first_array)];
  for (const Eigen::Vector4d& r : plant.roads_uv)
    fill_quad(img, f,
              {scenes::array_to_world(base, r[0], r[1]), scenes::array_to_world(base, r[2], r[1]),
               scenes::array_to_world(base, r[2], r[3]), scenes::array_to_world(base, r[0], r[3])},
              cv::Vec3b(225, 215, 195));
  if (plant.fence) {
    const scenes::Fence& fence = *plant.fence;
    const cv::Scalar grey(90, 90, 90), soil(205, 180, 140);
    for (std::size_t i = 0; i < fence.corners_m.size(); ++i)
      cv::line(img, f.px(fence.corners_m[i]), f.px(fence.corners_m[(i + 1) % fence.corners_m.size()]), grey, 2);
    for (std::size_t i = 0; i < fence.corners_m.size(); ++i) {
      const Eigen::Vector2d a = fence.corners_m[i], b = fence.corners_m[(i + 1) % fence.corners_m.size()];
      const Eigen::Vector2d d = (b - a).normalized();
      for (const Eigen::Vector2d& g : fence.gates_m)
        if (std::abs((g - a).x() * d.y() - (g - a).y() * d.x()) < 0.01)
          cv::line(img, f.px(g - d * fence.gate_width_m / 2), f.px(g + d * fence.gate_width_m / 2), soil, 3);
    }
  }
  for (const scenes::Fixture& fx : plant.fixtures) {
    const double a = fx.yaw_deg * M_PI / 180.0;
    const Eigen::Vector2d eu(std::cos(a), std::sin(a)), ev(-std::sin(a), std::cos(a));
    const double hu = std::max(fx.size_m.x() / 2, 0.75 / f.px_per_m), hv = std::max(fx.size_m.y() / 2, 0.75 / f.px_per_m);
    const cv::Vec3b rgb = fx.base_m >= 1.5 ? cv::Vec3b(120, 120, 130) : cv::Vec3b(40, 90, 200);
    fill_quad(img, f,
              {fx.centre_m - hu * eu - hv * ev, fx.centre_m + hu * eu - hv * ev, fx.centre_m + hu * eu + hv * ev,
               fx.centre_m - hu * eu + hv * ev},
              rgb);
  }
}

void draw_route(cv::Mat& img, const PlanFrame& f, const scenes::Scenario& s) {
  const std::vector<Eigen::Vector2d> route = scenes::route_polyline(s, 0.25);
  std::vector<cv::Point> pts;
  for (const Eigen::Vector2d& p : route) pts.push_back(f.px(p));
  const cv::Scalar colour(kPlanRouteRgb[0], kPlanRouteRgb[1], kPlanRouteRgb[2]);
  cv::polylines(img, pts, false, colour, 2, cv::LINE_AA);
  if (!pts.empty()) cv::circle(img, pts.front(), 6, colour, cv::FILLED, cv::LINE_AA);
}

/// The line under the plan: the station's name, its plant and its route.
std::string title_of(const scenes::Scenario& s) {
  std::string title = s.name;
  if (s.plant)
    title += format_number(": %.2f MWdc, ", s.plant->dc_mw) + std::to_string(s.plant->blocks) + " block(s) of " +
             std::to_string(s.plant->rows_per_block) + " rows";
  return title + format_number(", route %.0f m; north up", scenes::polyline_length(scenes::route_polyline(s, 0.25)));
}

int text_width_px(const std::string& text) {
  int baseline = 0;
  return cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &baseline).width;
}

/// A scale bar of a round length and the title, below the plan.
void draw_footer(cv::Mat& img, const PlanFrame& f, const scenes::Scenario& s) {
  const double target_m = 0.2 * f.width / f.px_per_m;
  double bar_m = std::pow(10.0, std::floor(std::log10(target_m)));
  for (double k : {5.0, 2.0})
    if (bar_m * k <= target_m) {
      bar_m *= k;
      break;
    }
  const int y = f.height + 14, x0 = 10, x1 = x0 + static_cast<int>(std::lround(bar_m * f.px_per_m));
  cv::line(img, {x0, y}, {x1, y}, cv::Scalar::all(0), 3);
  cv::putText(img, format_number("%.0f m", bar_m), {x1 + 8, y + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar::all(0), 1, cv::LINE_AA);
  cv::putText(img, title_of(s), {10, f.height + 36}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar::all(0), 1, cv::LINE_AA);
}

}  // namespace

cv::Mat make_plan_view(const scenes::Scenario& s, int max_side_px) {
  const PlanFrame f = frame_for(s, max_side_px);
  cv::Mat img(f.height + kFooterPx, std::max(f.width, text_width_px(title_of(s)) + 20), CV_8UC3,
              cv::Scalar::all(255));
  img(cv::Rect(0, 0, f.width, f.height)).setTo(cv::Scalar(205, 180, 140));  // soil
  draw_plant(img, f, s);
  draw_arrays(img, f, s);
  draw_walls(img, f, s);
  draw_route(img, f, s);
  draw_footer(img, f, s);
  return img;
}

}  // namespace pvb::run
