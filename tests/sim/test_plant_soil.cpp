// A plant's ground of shared soil images: ORB descriptors of 1 m² soil
// patches match only where two tiles took the same image (ORB does not see
// a quarter turn), and that happens to about one far pair in N images;
// near the camera, where every tile shows its own image, no far pair does.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "pvb/scenes/route.hpp"
#include "pvb/scenes/scenario.hpp"
#include "pvb/sim/scene_builder.hpp"
#include "pvb/sim/textures.hpp"

namespace pvb::test {
namespace plant_soil_test {

/// A pair of patches matches by the share of ORB features (on the smaller
/// side) with a cross-checked match within kMatchBits bits.
constexpr int kMatchBits = 40;
/// Patches of different images: at most this share of features matched.
constexpr double kDifferentMax = 0.10;

class Patches {
 public:
  /// own: each tile's own image, as it shows near the camera (GroundStream).
  explicit Patches(const scenes::Scenario& s, bool own = false) : s_(s), tiles_(sim::ground_tiles(s)), own_(own) {}
  const std::vector<sim::GroundTile>& tiles() const { return tiles_; }

  /// The 1 m² in the middle of tile k as the scene lays it (its image at its quarter turns), 2 px a texel.
  cv::Mat patch(std::size_t k) {
    const sim::GroundTile& t = tiles_[k];
    const std::uint64_t seed = own_ ? t.own_seed : t.seed;
    auto it = images_.find(seed);
    const scenes::GroundType type = t.gravel ? scenes::GroundType::kGravel : s_.ground.type;
    if (it == images_.end()) it = images_.emplace(seed, sim::make_ground_texture(type, seed)).first;
    cv::Mat img = it->second;
    for (int q = 0; q < t.quarter_turns; ++q) cv::rotate(img.clone(), img, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int side = static_cast<int>(img.cols / sim::kGroundTileM);  // 1 m
    cv::Mat grey, big;
    cv::cvtColor(img(cv::Rect((img.cols - side) / 2, (img.rows - side) / 2, side, side)), grey, cv::COLOR_RGB2GRAY);
    cv::resize(grey, big, cv::Size(), 2.0, 2.0, cv::INTER_LINEAR);
    return big;
  }

  /// The share of features of the smaller side matched between tiles a and b.
  double match_share(std::size_t a, std::size_t b) {
    const Features& fa = features(a);
    const Features& fb = features(b);
    if (fa.descriptors.empty() || fb.descriptors.empty()) return 0.0;
    cv::BFMatcher matcher(cv::NORM_HAMMING, true);
    std::vector<cv::DMatch> matches;
    matcher.match(fa.descriptors, fb.descriptors, matches);
    int good = 0;
    for (const cv::DMatch& m : matches) good += m.distance < kMatchBits ? 1 : 0;
    return static_cast<double>(good) / std::min(fa.descriptors.rows, fb.descriptors.rows);
  }

 private:
  struct Features {
    cv::Mat descriptors;
  };
  const Features& features(std::size_t k) {
    auto it = features_.find(k);
    if (it != features_.end()) return it->second;
    cv::Ptr<cv::ORB> orb = cv::ORB::create(300);
    std::vector<cv::KeyPoint> kp;
    Features f;
    orb->detectAndCompute(patch(k), cv::noArray(), kp, f.descriptors);
    return features_.emplace(k, f).first->second;
  }
  scenes::Scenario s_;
  std::vector<sim::GroundTile> tiles_;
  bool own_ = false;
  std::map<std::uint64_t, cv::Mat> images_;
  std::map<std::size_t, Features> features_;
};

double mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

TEST(PlantSoil, FarPatchesMatchOnlyWhereTheyTookTheSameImage) {
  const scenes::Scenario s =
      scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/plants/plant_10mw_tracker.yaml");
  ASSERT_GT(s.ground.soil_images, 0);
  Patches p(s);
  const std::vector<sim::GroundTile>& t = p.tiles();
  ASSERT_GT(t.size(), 500u);
  std::vector<double> far_different, far_same, different;
  const std::size_t step = t.size() / 40;
  for (std::size_t a = 0; a < t.size(); a += step)
    for (std::size_t b = a + step / 2; b < t.size(); b += step) {
      const double share = p.match_share(a, b);
      const bool same_image = t[a].image == t[b].image;
      if (!same_image) different.push_back(share);
      if ((t[a].centre_m - t[b].centre_m).norm() >= 50.0) (same_image ? far_same : far_different).push_back(share);
    }
  ASSERT_GE(far_different.size(), 200u);
  const std::size_t far = far_different.size() + far_same.size();
  std::printf("matched share: far pairs of different images mean %.4f max %.4f (%zu), far pairs of one image mean "
              "%.4f (%zu of %zu far pairs; 1/%d expected)\n",
              mean(far_different), *std::max_element(far_different.begin(), far_different.end()),
              far_different.size(), mean(far_same), far_same.size(), far, s.ground.soil_images);
  // Two patches of different images never match...
  for (double share : different) EXPECT_LT(share, kDifferentMax);
  // ...two of one image do, whatever their quarter turns (so a repeated
  // ground, one image everywhere, matches everywhere)...
  for (double share : far_same) EXPECT_GT(share, 0.5);
  // ...and one far pair in soil_images takes the same image (at most three
  // times that: a binomial count of about 5 in 330 pairs stays below it).
  EXPECT_LE(static_cast<double>(far_same.size()) / far, 3.0 / s.ground.soil_images);
}

// Near the camera every tile shows an image of its own
// (ground.unique_within_m): there no two patches 50 m or more apart match,
// any more than patches of different images do.
TEST(PlantSoil, NearTheCameraNoFarPatchesMatch) {
  const scenes::Scenario s =
      scenes::load_scenario(std::string(PVB_SOURCE_DIR) + "/scenes/plants/plant_10mw_tracker.yaml");
  ASSERT_GT(s.ground.unique_within_m, 0.0);
  Patches p(s, true);
  const std::vector<sim::GroundTile>& t = p.tiles();
  std::vector<double> far;
  const std::size_t step = t.size() / 40;
  for (std::size_t a = 0; a < t.size(); a += step)
    for (std::size_t b = a + step / 2; b < t.size(); b += step)
      if ((t[a].centre_m - t[b].centre_m).norm() >= 50.0) far.push_back(p.match_share(a, b));
  ASSERT_GE(far.size(), 300u);
  std::printf("own images: far pairs matched share mean %.4f max %.4f (%zu pairs)\n", mean(far),
              *std::max_element(far.begin(), far.end()), far.size());
  for (double share : far) EXPECT_LT(share, kDifferentMax);
}

// A plant's service roads are gravel: a tile whose centre lies on a road
// takes one of the road's images, every other tile a soil image.
TEST(PlantSoil, TilesOnTheRoadsTakeGravelImages) {
  const scenes::Scenario s = scenes::parse_scenario(
      "ground: {size_m: [200, 160], tiling: varied, soil_images: 8}\n"
      "plant: {origin_m: [-40, -20], rows: 6, tables_per_row: 2, modules_per_table: 20}\n"
      "route: {pattern: roads}\n",
      "roads.yaml");
  const scenes::PvArray& frame = s.pv_arrays[static_cast<std::size_t>(s.plant->first_array)];
  int gravel = 0, soil = 0;
  for (const sim::GroundTile& t : sim::ground_tiles(s)) {
    const Eigen::Vector2d uv = scenes::world_to_array(frame, t.centre_m);
    bool on_road = false;
    for (const Eigen::Vector4d& r : s.plant->roads_uv)
      on_road = on_road || (uv.x() >= r[0] && uv.x() <= r[2] && uv.y() >= r[1] && uv.y() <= r[3]);
    if (on_road) {
      ++gravel;
      EXPECT_GE(t.image, 8);
      EXPECT_LT(t.image, 8 + sim::kRoadGravelImages);
    } else {
      ++soil;
      EXPECT_LT(t.image, 8);
    }
  }
  EXPECT_GT(gravel, 100);  // the loop drives the road all the way round
  EXPECT_GT(soil, 10);     // the ground beside it
  // The scene draws the road's images as gravel.
  const sim::SceneAssets a = sim::build_scene(s, sim::SceneDetail::kFull, sim::TextureEncoding::kPixels);
  const auto n = std::count_if(a.files.begin(), a.files.end(),
                               [](const auto& f) { return f.first.rfind("textures/groundt", 0) == 0; });
  EXPECT_EQ(n, 8 + sim::kRoadGravelImages);
}

}  // namespace plant_soil_test
}  // namespace pvb::test
