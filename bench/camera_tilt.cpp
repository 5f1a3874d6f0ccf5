// Not a benchmark: the camera's true pitch and roll over a drive, from the
// ground truth of recordings (groundtruth.txt), as a CSV and a line chart.
//   camera_tilt --out DIR LABEL=RECORDING/groundtruth.txt [LABEL=...]
// Pitch is the optical axis's angle above the horizontal, roll the image x
// axis's (right) angle above it, both in degrees.  Writes DIR/tilt.csv
// (label, t_s, pitch_deg, roll_deg) and DIR/tilt.png (pitch and roll
// against time), and prints each drive's mean and standard deviation.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/eval/trajectory.hpp"
#include "pvb/plot/png.hpp"

namespace {

struct Drive {
  std::string label;
  std::vector<double> t_s, pitch_deg, roll_deg;
};

Drive tilt_of(const std::string& label, const std::string& path) {
  const pvb::eval::Trajectory gt = pvb::eval::read_tum(path);
  Drive d{label, {}, {}, {}};
  for (const auto& p : gt.poses) {
    const Eigen::Matrix3d R = p.T_w_c.linear();  // columns: the optical x (right), y (down), z (forward) axes
    d.t_s.push_back(1e-9 * static_cast<double>(p.t_ns - gt.t_begin_ns()));
    d.pitch_deg.push_back(std::asin(R(2, 2)) * 180 / M_PI);
    d.roll_deg.push_back(std::asin(R(2, 0)) * 180 / M_PI);
  }
  return d;
}

void mean_std(const std::vector<double>& v, double* mean, double* sd) {
  double m = 0, s = 0;
  for (double x : v) m += x / static_cast<double>(v.size());
  for (double x : v) s += (x - m) * (x - m) / static_cast<double>(v.size());
  *mean = m;
  *sd = std::sqrt(s);
}

}  // namespace

int main(int argc, char** argv) {
  std::string out;
  std::vector<Drive> drives;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--out" && i + 1 < argc) {
        out = argv[++i];
      } else if (const std::size_t eq = a.find('='); eq != std::string::npos) {
        drives.push_back(tilt_of(a.substr(0, eq), a.substr(eq + 1)));
      } else {
        std::fprintf(stderr, "usage: camera_tilt --out DIR LABEL=groundtruth.txt [LABEL=...]\n");
        return 2;
      }
    }
    if (out.empty() || drives.empty()) {
      std::fprintf(stderr, "usage: camera_tilt --out DIR LABEL=groundtruth.txt [LABEL=...]\n");
      return 2;
    }
    std::string csv = "label,t_s,pitch_deg,roll_deg\n";
    std::vector<pvb::eval::Series> series;
    for (const Drive& d : drives) {
      for (std::size_t k = 0; k < d.t_s.size(); ++k)
        csv += d.label + "," + pvb::format_number("%.4f", d.t_s[k]) + "," +
               pvb::format_number("%.4f", d.pitch_deg[k]) + "," + pvb::format_number("%.4f", d.roll_deg[k]) +
               "\n";
      series.push_back({d.label + " pitch", d.t_s, d.pitch_deg, pvb::eval::series_color(series.size())});
      series.push_back({d.label + " roll", d.t_s, d.roll_deg, pvb::eval::series_color(series.size())});
      double pm = 0, ps = 0, rm = 0, rs = 0;
      mean_std(d.pitch_deg, &pm, &ps);
      mean_std(d.roll_deg, &rm, &rs);
      std::printf("%s: %zu poses, pitch %.3f +- %.3f deg, roll %.3f +- %.3f deg (mean +- std)\n",
                  d.label.c_str(), d.t_s.size(), pm, ps, rm, rs);
    }
    pvb::write_file(out + "/tilt.csv", csv);
    pvb::plot::write_png(
        pvb::eval::make_line_chart("camera pitch and roll over the drive", "time, s", "degrees", series),
        out + "/tilt.png");
  } catch (const pvb::Error& e) {
    std::fprintf(stderr, "camera_tilt: %s\n", e.what());
    return 1;
  }
  return 0;
}
