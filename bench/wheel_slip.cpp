// Drives scenarios' robots (physics only, no rendering) and charts each
// wheel's slip per encoder reading against the commanded wheel speed, with
// the wheel odometry's drift: how one station's days differ under the tyres.
//   wheel_slip --out DIR LABEL=scenario.yaml [LABEL=scenario.yaml ...]
// writes DIR/slip.csv, DIR/slip.png (slip over time) and
// DIR/slip_commanded.png (the commanded wheel speeds).
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/charts.hpp"
#include "pvb/geometry/time.hpp"
#include "pvb/plot/png.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/simulator.hpp"

namespace {

struct Day {
  std::string label;
  std::vector<double> t_s, slip_left, slip_right, commanded_left;
  double drift_m = 0, distance_m = 0;
};

Day drive(const std::string& label, const std::string& file) {
  const pvb::scenes::Scenario s = pvb::scenes::load_scenario(file);
  pvb::sim::Simulator sim(s);
  pvb::sensor::WheelOdometry odo(pvb::sim::nominal_description(s));
  Day d{label, {}, {}, {}, {}};
  std::vector<pvb::sim::WheelTruth> truth;
  for (int i = 1; i < sim.frame_count(); ++i) {
    sim.advance();
    const pvb::sim::MotionBatch b = sim.take_motion();
    for (std::size_t k = 0; k < b.ticks.size(); ++k) {
      odo.add(b.ticks[k]);
      truth.push_back(b.wheel_truth[k]);
    }
  }
  for (std::size_t k = 0; k < truth.size(); ++k) {
    d.t_s.push_back(pvb::geom::ns_to_seconds(truth[k].t_ns));
    d.slip_left.push_back(truth[k].slip.x());
    d.slip_right.push_back(truth[k].slip.y());
    d.commanded_left.push_back(truth[k].commanded_radps.x());
    if (k > 0) d.distance_m += (truth[k].T_w_b.translation() - truth[k - 1].T_w_b.translation()).head<2>().norm();
  }
  const Eigen::Vector2d p_o = pvb::sensor::odometry_frame_position(truth.front().T_w_b, truth.back().T_w_b);
  d.drift_m = (Eigen::Vector2d(odo.state().x_m, odo.state().y_m) - p_o).norm();
  return d;
}

double mean_abs(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += std::abs(x);
  return v.empty() ? 0 : s / v.size();
}

}  // namespace

int main(int argc, char** argv) {
  const char* usage = "usage: wheel_slip --out DIR LABEL=scenario.yaml [LABEL=scenario.yaml ...]\n";
  std::string out;
  std::vector<Day> days;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--out" && i + 1 < argc) {
        out = argv[++i];
      } else if (const std::size_t eq = a.find('='); eq != std::string::npos) {
        days.push_back(drive(a.substr(0, eq), a.substr(eq + 1)));
      } else {
        std::fputs(usage, stderr);
        return 2;
      }
    }
    if (out.empty() || days.empty()) {
      std::fputs(usage, stderr);
      return 2;
    }
    std::string csv = "label,t_s,slip_left,slip_right,commanded_left_radps\n";
    std::vector<pvb::eval::Series> slip, commanded;
    for (const Day& d : days) {
      for (std::size_t k = 0; k < d.t_s.size(); ++k)
        csv += d.label + "," + pvb::format_number("%.3f", d.t_s[k]) + "," + pvb::format_g(d.slip_left[k], 6) + "," +
               pvb::format_g(d.slip_right[k], 6) + "," + pvb::format_g(d.commanded_left[k], 6) + "\n";
      slip.push_back({d.label + " left", d.t_s, d.slip_left, pvb::eval::series_color(slip.size())});
      commanded.push_back({d.label, d.t_s, d.commanded_left, pvb::eval::series_color(commanded.size())});
      std::printf("%s: mean |slip| left %.4f right %.4f; odometry %.3f m off after %.2f m (%.2f %%)\n",
                  d.label.c_str(), mean_abs(d.slip_left), mean_abs(d.slip_right), d.drift_m, d.distance_m,
                  100 * d.drift_m / d.distance_m);
    }
    pvb::write_file(out + "/slip.csv", csv);
    pvb::plot::write_png(pvb::eval::make_line_chart("left wheel slip per encoder reading", "time, s",
                                                    "slip (wheel speed x radius - ground speed) / larger", slip),
                         out + "/slip.png");
    pvb::plot::write_png(pvb::eval::make_line_chart("commanded left wheel speed", "time, s", "rad/s", commanded),
                         out + "/slip_commanded.png");
  } catch (const pvb::Error& e) {
    std::fprintf(stderr, "wheel_slip: %s\n", e.what());
    return 1;
  }
  return 0;
}
