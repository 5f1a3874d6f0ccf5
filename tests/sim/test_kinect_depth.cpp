// The depth of a fakenect dump against the simulator's truth: rendered
// pv_station depth, encoded as a Kinect v1's raw IR-view disparity
// (sensor::kinect, as `pvbench record --format fakenect` writes it) and
// registered back to the colour view (as the freenect:// plug-in serves it).
// Per range bin, the error must be the documented quantisation: a raw value
// is the disparity rounded to its step, so |error| is uniform up to half a
// step plus libfreenect's truncation to whole millimetres (< 1 mm); its
// median is a quarter step.  Only edge pixels (occlusion shadow, dense fill)
// may do worse.  The table is printed: docs/openni.md quotes it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sensor/kinect_v1.hpp"
#include "pvb/sim/sim_frame_source.hpp"

namespace {

namespace kinect = pvb::sensor::kinect;

struct Bin {
  double lo_m, hi_m;
  std::vector<double> abs_err_mm;
  long truth = 0, served = 0;
};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<long>(k), v.end());
  return v[k];
}

}  // namespace

TEST(KinectDepth, DumpDepthErrorIsTheQuantisationPerRangeBin) {
  pvb::scenes::Scenario s = pvb::scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/pv_station.yaml");
  constexpr int kFrames = 60;
  pvb::sim::SimFrameSource src(s, pvb::sim::GlBackend::kAuto, kFrames);
  const kinect::DepthRegistration reg{kinect::Calibration{}};
  std::vector<Bin> bins = {{0.5, 1.5, {}}, {1.5, 2.0, {}}, {2.0, 2.5, {}}, {2.5, 3.0, {}},
                           {3.0, 3.5, {}}, {3.5, 4.0, {}}, {4.0, 4.5, {}}};
  for (int i = 0; i < kFrames; ++i) {
    ASSERT_TRUE(src.next());
    if (i % 10) continue;
    cv::Mat truth = src.last_depth_gt_m().clone();
    truth.setTo(0.0f, (truth < s.camera.depth_range_m[0]) | (truth > s.camera.depth_range_m[1]));
    const cv::Mat served = reg.register_to_colour_mm(reg.encode_ir_raw(truth));
    for (int v = 0; v < truth.rows; ++v)
      for (int u = 0; u < truth.cols; ++u) {
        const double z_m = truth.at<float>(v, u);
        for (Bin& b : bins) {
          if (z_m < b.lo_m || z_m >= b.hi_m) continue;
          ++b.truth;
          const std::uint16_t mm = served.at<std::uint16_t>(v, u);
          if (mm == 0) continue;
          ++b.served;
          b.abs_err_mm.push_back(std::abs(mm - 1000.0 * z_m));
        }
      }
  }
  std::printf("range m    | pixels   | served  | step mm | median |e| mm | p90 |e| mm | within step/2+1 mm\n");
  int judged = 0;
  for (const Bin& b : bins) {
    if (b.truth < 10000) {  // the camera looks down from 1.1 m: little is near
      std::printf("%.1f-%.1f    | %8ld | (too few pixels to judge)\n", b.lo_m, b.hi_m, b.truth);
      continue;
    }
    ++judged;
    const double step_lo = kinect::quantisation_step_mm(1000 * b.lo_m, reg.calibration());
    const double step_hi = kinect::quantisation_step_mm(1000 * b.hi_m, reg.calibration());
    const double bound_hi = 0.5 * step_hi + 1.0;
    const double within =
        static_cast<double>(std::count_if(b.abs_err_mm.begin(), b.abs_err_mm.end(),
                                          [&](double e) { return e <= bound_hi; })) /
        static_cast<double>(b.abs_err_mm.size());
    const double med = quantile(b.abs_err_mm, 0.5), p90 = quantile(b.abs_err_mm, 0.9);
    std::printf("%.1f-%.1f    | %8ld | %5.1f %% | %.1f-%.1f | %6.2f | %6.2f | %5.1f %%\n", b.lo_m, b.hi_m, b.truth,
                100.0 * b.served / b.truth, step_lo, step_hi, med, p90, 100.0 * within);
    EXPECT_GT(static_cast<double>(b.served) / b.truth, 0.95) << b.lo_m;  // shadows are thin
    EXPECT_LE(med, 0.25 * step_hi + 1.0) << b.lo_m;
    EXPECT_GE(within, 0.95) << b.lo_m;
  }
  EXPECT_GE(judged, 5);
}
