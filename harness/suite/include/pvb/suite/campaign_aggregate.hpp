#pragma once
// Aggregation of a campaign swept over seeds: DIR/seed_S/campaign.json of
// every seed, per session the shares of frames localised within (0.05 m,
// 1 deg) and (0.25 m, 2 deg) with their mean, 95 % interval and worst seed,
// the wrong-place poses over all seeds, frames to the first pose, and the
// keyframes each session added (docs/map_reuse.md).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pvb/suite/aggregate.hpp"

namespace pvb::suite {

/// One session of one seed, as campaign.json gives it.
struct CampaignSessionMetrics {
  std::string name, mode, map;  ///< map: "" for a map session
  std::string status;           ///< "completed", ... or "" when it failed
  std::string error;
  int frames = 0, lost_frames = 0, keyframes = 0, keyframes_loaded = 0;
  double tracking_ms_median = 0;
  std::optional<double> share_fine, share_high;  ///< with localisation scores
  std::optional<int> wrong_place, first_pose_frame;
};

struct CampaignSeed {
  std::uint64_t seed = 0;
  std::string error;  ///< why there is no campaign.json
  std::string campaign;
  std::vector<CampaignSessionMetrics> sessions;
};

/// Reads DIR/seed_S/campaign.json; a missing or bad file is the seed's error.
CampaignSeed read_campaign_seed(std::uint64_t seed, const std::string& path);

/// Per session over the seeds.
struct CampaignSessionAggregate {
  std::string name, mode, map;
  int seeds = 0;   ///< seeds where the session ran
  int failed = 0;  ///< seeds where it did not complete
  Summary fine, high;          ///< shares, over the seeds with scores
  double fine_ci95 = 0, high_ci95 = 0;  ///< half-widths of the 95 % intervals of the means
  int wrong_place = 0;         ///< over all seeds
  Summary first_pose_frame;    ///< over the seeds with a pose
  int never_posed = 0;         ///< seeds without any pose
  Summary keyframes_added;     ///< keyframes at the end minus those loaded
  Summary tracking_ms_median;
};

struct CampaignAggregate {
  std::string campaign;
  std::vector<std::uint64_t> seeds;
  std::vector<std::string> seed_errors;  ///< "seed S: why" for seeds without results
  std::vector<CampaignSessionAggregate> sessions;
};

CampaignAggregate aggregate_campaign(const std::vector<CampaignSeed>& seeds);
std::string format_campaign_markdown(const CampaignAggregate& a);
std::string format_campaign_json(const CampaignAggregate& a);

}  // namespace pvb::suite
