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

/// The campaign a sweep's seeds ran: its file's name and sessions in order.
/// A seed's campaign.json must be of it.
struct ExpectedCampaign {
  std::string file;  ///< the campaign file, for messages
  std::string name;
  struct Session {
    std::string name, mode, map;  ///< map: "" for a map session
  };
  std::vector<Session> sessions;
};

/// One session of one seed, as campaign.json gives it.
struct CampaignSessionMetrics {
  std::string name, mode, map;  ///< map: "" for a map session
  /// completed, interrupted, aborted (the run's), failed, skipped or not_run
  /// (version 1 files: null reads as failed).
  std::string status;
  std::string error;
  std::optional<std::uint64_t> seed;  ///< absent in a version 1 file's session that did not run
  /// The run's figures, absent for a session that did not run.
  std::optional<int> frames, lost_frames, keyframes, keyframes_loaded;
  std::optional<double> tracking_ms_median;
  std::optional<double> share_fine, share_high;  ///< with localisation scores
  std::optional<int> wrong_place, first_pose_frame;
  bool completed() const { return status == "completed"; }
};

struct CampaignSeed {
  std::uint64_t seed = 0;  ///< the seed folder's
  std::string path;        ///< its campaign.json
  std::string error;       ///< why there are no figures ("" when read)
  int version = 0;         ///< "campaign_version"
  std::string campaign;
  std::optional<std::uint64_t> file_seed;  ///< "seed" (null: run without --seed)
  std::vector<CampaignSessionMetrics> sessions;
};

/// The newest campaign.json this program reads: the version `pvbench
/// campaign` writes (run::kCampaignJsonVersion).
inline constexpr int kCampaignVersionRead = 2;

/// Reads DIR/seed_S/campaign.json (campaign_version 1 or 2).  A missing
/// file, one that is not a regular file or not JSON, a newer version, and
/// a field missing, of the wrong type or out of its range (a quoted number
/// is a string) are the seed's error, naming the file, the line and the key.
CampaignSeed read_campaign_seed(std::uint64_t seed, const std::string& path);

/// Refuses the campaign.json of another campaign or seed: throws ConfigError
/// naming the file and the key when its "campaign" is not `expected`'s name,
/// its "seed" not the folder's, its sessions not the campaign file's (names,
/// modes and maps, in order; a version 1 file may end early, as a stopped
/// campaign left it) or a session's seed not seed × 1000 + i.
void expect_campaign_identity(const CampaignSeed& c, const ExpectedCampaign& expected);

/// Per session over the seeds.
struct CampaignSessionAggregate {
  std::string name, mode, map;
  int seeds = 0;               ///< seeds with a campaign.json
  int failed = 0;              ///< of those, the seeds where the session did not complete
  Summary fine, high;          ///< shares, over the seeds with scores
  double fine_ci95 = 0, high_ci95 = 0;  ///< half-widths of the 95 % intervals of the means
  int wrong_place = 0;         ///< over all seeds
  Summary first_pose_frame;    ///< over the seeds with a pose
  int never_posed = 0;         ///< seeds without any pose
  Summary keyframes_added;     ///< keyframes at the end minus those loaded (completed sessions)
  Summary tracking_ms_median;  ///< over the seeds that tracked a frame
};

struct CampaignAggregate {
  std::string campaign;
  std::vector<std::uint64_t> seeds;
  std::vector<std::string> seed_errors;  ///< "seed S: why" for seeds without results
  std::vector<CampaignSessionAggregate> sessions;  ///< every session of the campaign, in order
};

CampaignAggregate aggregate_campaign(const ExpectedCampaign& campaign,
                                     const std::vector<CampaignSeed>& seeds);
std::string format_campaign_markdown(const CampaignAggregate& a);
std::string format_campaign_json(const CampaignAggregate& a);

}  // namespace pvb::suite
