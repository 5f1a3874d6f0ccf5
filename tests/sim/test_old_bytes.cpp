// Golden hashes of the old bytes.  Every shipped scenario keeps a way to
// what it produced before the outdoor sensor models: with the Kinect
// model (`camera.model: kinect`), no sunlight on its pattern
// (`depth_noise.sunlight: off`), diffuse panel glass (`glass: diffuse`) and
// a repeated soil (`ground.tiling: repeat`), its scene (MJCF and textures)
// and the sensor model's output on a fixed input hash as pinned here.  A
// change of these hashes is a change of every recording made with these
// switches: make it on purpose, and say so.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/sensor_model.hpp"

using namespace pvb;

namespace {

/// FNV-1a, 64 bits.
struct Fnv {
  std::uint64_t h = 1469598103934665603ull;
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
  }
  void add(const std::string& s) { add(s.data(), s.size()); }
  void add(const cv::Mat& m) {
    for (int r = 0; r < m.rows; ++r) add(m.ptr(r), m.cols * m.elemSize());
  }
};

/// The scenario with every switch at its old bytes.
scenes::Scenario with_old_switches(scenes::Scenario s) {
  s.camera.model = scenes::CameraModel::kKinect;
  s.camera.depth_noise.sunlight.on = false;
  for (auto& a : s.pv_arrays) a.specular_glass = false;
  s.ground.tiling = scenes::GroundTiling::kRepeat;
  return s;
}

std::uint64_t scene_hash(const scenes::Scenario& s) {
  const sim::SceneAssets a = sim::build_scene(s);
  Fnv f;
  f.add(a.xml);
  for (const auto& [path, bytes] : a.files) {
    f.add(path);
    f.add(bytes.data(), bytes.size());
  }
  return f.h;
}

}  // namespace

TEST(OldBytes, TheDefaultStationsSceneWithTheOldSwitches) {
  // pv_station and its tracker and rough siblings, as the bench drew them
  // before the outdoor sensor models.
  const std::map<std::string, std::uint64_t> pinned = {
      {"pv_station.yaml", 0xf193bcc1507bf74cull},
      {"tracker_station.yaml", 0x1f073f2fd59f5214ull},
      {"rough_station.yaml", 0x114a8572773997caull},
  };
  for (const auto& [file, hash] : pinned) {
    const auto s = with_old_switches(scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/" + file));
    EXPECT_EQ(scene_hash(s), hash) << file << ": 0x" << std::hex << scene_hash(s);
  }
}

TEST(OldBytes, TheKinectModelOnAFixedInput) {
  scenes::Camera cam;  // the Kinect model's defaults
  const geom::PinholeIntrinsics K{cam.fx, cam.fy, cam.cx(), cam.cy(), cam.width, cam.height};
  cv::Mat depth(cam.height, cam.width, CV_32FC1), rgb(cam.height, cam.width, CV_8UC3);
  for (int r = 0; r < cam.height; ++r)
    for (int c = 0; c < cam.width; ++c) {
      depth.at<float>(r, c) = r < 40 ? 0.0f : 0.8f + 3.0f * static_cast<float>(r) / cam.height + 0.001f * (c % 37);
      rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uchar>(c % 251), static_cast<uchar>(r % 241),
                                          static_cast<uchar>((r * c) % 239));
    }
  Fnv d;
  d.add(sim::apply_depth_model(depth, K, cam, 7, 3));
  scenes::RgbNoise noise = cam.rgb;
  noise.glare = 0.3;
  noise.auto_exposure = true;
  sim::apply_rgb_model(&rgb, noise, cv::Point2d(500, 100), 7, 3);
  Fnv c;
  c.add(rgb);
  EXPECT_EQ(d.h, 0xdfbbb0921853fa69ull) << "depth 0x" << std::hex << d.h;
  EXPECT_EQ(c.h, 0xf67738132c015d6bull) << "colour 0x" << std::hex << c.h;
}
