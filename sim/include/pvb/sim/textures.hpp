#pragma once
// Procedural textures for the photovoltaic station, generated from a seed.
// All images are CV_8UC3 in R, G, B order.
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>
#include <string>

#include "pvb/scenes/scenario.hpp"

namespace pvb::sim {

/// One PV module seen from the front: an aluminium frame, cells with
/// busbars on dark glass (drawn from the station's seed), and the day's dust
/// (from the day's seed: denser towards the lower edge) and stains.  The
/// image's top row is the panel's upper edge.
cv::Mat make_panel_texture(const scenes::PvArray& array, double dirt, std::uint64_t station_seed,
                           std::uint64_t day_seed);
/// Grey bricks of high similarity in running bond; the image covers
/// kBrickTileWidthM x kBrickTileHeightM of wall.
cv::Mat make_brick_texture(std::uint64_t seed);
constexpr double kBrickTileWidthM = 0.90;   // 4 bricks of 0.215 m + 10 mm joints
constexpr double kBrickTileHeightM = 0.75;  // 10 courses of 0.065 m + 10 mm joints
/// Soil or gravel; the image covers kGroundTileM x kGroundTileM.
cv::Mat make_ground_texture(scenes::GroundType type, std::uint64_t seed);
constexpr double kGroundTileM = 3.0;
/// The side of a ground image, pixels (512: a texel of 6 mm).
constexpr int kGroundTexturePx = 512;
/// The textures that hold the images of a ground's tiles near the camera
/// (GroundStream): grounds0, grounds1, ...
constexpr const char* kGroundSlotPrefix = "grounds";
/// MuJoCo 2.2.2's render context holds the names of at most 100 textures
/// (mjrContext::texture[100], although mjMAXTEXTURE says 1000): a model
/// with more corrupts the context.  Every scene stays within it.
constexpr int kMaxSceneTextures = 100;
/// How many tile images a ground keeps near the camera: every tile with a
/// point within `within_m` of the camera (a centre within within_m plus
/// half a tile's diagonal) fits, wherever the camera stands.
int unique_ground_slots(double within_m);
/// A varied ground (ground.tiling: varied) gives every 3 m tile within
/// this distance of the route an image of its own (the camera resolves the
/// soil's stones closer than that); the repeated image lies beyond.
constexpr double kGroundVariedCorridorM = 4.0;
/// At most this many varied tiles with an image each (a route of about
/// 55 m): 512 x 512 RGB each, and a texture each within kMaxSceneTextures.
constexpr int kMaxGroundTiles = 80;
/// At most this many tiles on a ground of `soil_images` shared images (a
/// route of several kilometres): a plane geom each, culled to the view.
constexpr int kMaxSharedImageTiles = 20000;
/// A plant's service roads, on a ground of shared soil images: every tile
/// whose centre lies on a road takes one of this many gravel images instead
/// (after the soil images: groundt{soil_images + k}).
constexpr int kRoadGravelImages = 8;
/// The soil's stones, about 4 cm: a ground tile farther than where they
/// shrink below half a pixel shows nothing the repeated soil under it does
/// not (fx x 0.04 / 0.5: 42 m at fx 525).
constexpr double kSoilFeatureM = 0.04;
/// The plates of a plant's row signs: each label (two words, "B1 R017")
/// black on white in its own cell of kSignCellPx, kSignAtlasColumns cells
/// a line, first word small above the second.
cv::Mat make_sign_atlas(const std::vector<std::string>& labels);
inline constexpr int kSignCellWidthPx = 144, kSignCellHeightPx = 96, kSignAtlasColumns = 16;
/// Tyre tracks: compacted, darker soil with the tread's bars across the
/// track; the image covers kCoverTileM x kCoverTileM, its x along the track.
cv::Mat make_track_texture(std::uint64_t seed);
/// Grass and weeds on soil, the same size.
cv::Mat make_grass_texture(std::uint64_t seed);
inline constexpr double kCoverTileM = 0.5;
/// Leaves for shrubs and tree crowns.
cv::Mat make_foliage_texture(std::uint64_t seed);
/// Tree bark.
cv::Mat make_bark_texture(std::uint64_t seed);

}  // namespace pvb::sim
