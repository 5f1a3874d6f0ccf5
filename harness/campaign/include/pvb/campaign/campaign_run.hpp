#pragma once
// Running a campaign: its sessions in order, each a scenario run in its
// folder (OUT/SESSION), the maps passed along in OUT/maps/SESSION.pvbmap,
// then OUT/campaign.json, OUT/campaign.md, the matrix figure (map session
// x query session, coloured by the share of frames within 0.25 m and 2 deg)
// and OUT/index.html (docs/map_reuse.md).
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "pvb/campaign/campaign.hpp"
#include "pvb/plot/matrix.hpp"
#include "pvb/report/map_report.hpp"
#include "pvb/report/report.hpp"

namespace pvb::run {

struct CampaignOptions {
  std::string campaign_file;
  std::string out_dir;
  bool overwrite = false;
  /// Session i runs with seed * 1000 + i (the station seed stays the
  /// scenario's); nullopt: each scenario's own seed.
  std::optional<std::uint64_t> seed;
  int max_frames = 0;  ///< per session (0: the scenario's duration)
  bool sync = false;
  bool map_eval = true;
  std::string gl = "auto";
  const std::atomic<bool>* stop = nullptr;
  std::function<void(const std::string&)> on_log;
};

/// How a session ended: its run's own status, or why it has none.
enum class SessionStatus {
  kCompleted,    ///< the run's status (metrics.json "status")
  kInterrupted,  ///< the run was stopped by SIGINT/SIGTERM: its figures are partial
  kAborted,      ///< the run's route.on_loss stopped it
  kFailed,       ///< the run stopped with an error
  kSkipped,      ///< its map session left no map
  kNotRun,       ///< the campaign was stopped before it (or has not reached it yet)
};
/// "completed", "interrupted", "aborted", "failed", "skipped", "not_run".
const char* to_string(SessionStatus s);

/// One session's outcome.
struct SessionResult {
  CampaignSession session;
  std::uint64_t seed = 0;  ///< the seed it runs (or would have run) with
  SessionStatus status = SessionStatus::kNotRun;
  std::string error;  ///< why it failed or was skipped ("" otherwise)
  // The run's figures: meaningful only when ran() (a session without a run
  // has null figures in campaign.json and "-" in campaign.md).
  std::size_t frames = 0, lost_frames = 0, keyframes = 0;
  std::size_t keyframes_loaded = 0;  ///< in the map it started from (0 for a new map)
  std::optional<double> ate_rmse_m;
  std::optional<double> tracking_ms_median;  ///< none without a tracked frame
  std::optional<MapReport> map;
  /// Completed, interrupted or aborted: the run wrote its report.
  bool ran() const;
};

struct CampaignReport {
  Campaign campaign;
  std::optional<std::uint64_t> seed;
  std::vector<SessionResult> sessions;
  bool stopped = false;
};

/// Runs every session in order.  A session whose map is missing (its map
/// session failed) is skipped with the reason; once stopped, the sessions
/// left are not run.  Every session of the file is in the report, with its
/// status.  Throws pvb::Error for a bad campaign file or output folder.
CampaignReport run_campaign(const CampaignOptions& options);

/// campaign.json's "campaign_version": 2 since every session of the file is
/// listed with its status, and a figure a session lacks is null.
inline constexpr int kCampaignJsonVersion = 2;
/// campaign.json: the campaign, its seed and each session's status and figures.
std::string campaign_json(const CampaignReport& r);
/// campaign.md: one row per session of the file, with its status.
std::string campaign_markdown(const CampaignReport& r);
/// index.html: campaign.md, the matrix and a link to each session's report.
std::string campaign_html(const CampaignReport& r, const std::string& markdown);
/// One session's place in a campaign matrix: what it is, the session
/// whose map it used, and its share within (0.25 m, 2 deg) when measured.
struct MatrixSession {
  std::string name;
  SessionMode mode = SessionMode::kMap;
  std::string map;
  std::optional<double> share;
};
/// The matrix: rows the sessions that leave a map, columns those that start
/// from one, each cell a query session's share in its map session's row.
plot::MatrixFigure campaign_matrix(const std::string& title, const std::vector<MatrixSession>& sessions);
/// The matrix of one run of a campaign.
plot::MatrixFigure campaign_matrix(const CampaignReport& r);
/// 0 when every session completed, else non-zero.
int campaign_exit_code(const CampaignReport& r);

}  // namespace pvb::run
