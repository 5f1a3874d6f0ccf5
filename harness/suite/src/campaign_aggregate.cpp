#include "pvb/suite/campaign_aggregate.hpp"

#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <filesystem>
#include <set>

#include "json_fields.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::suite {
namespace {

using detail::JsonFields;

const std::set<std::string> kRunStatuses = {"completed", "interrupted", "aborted"};
const std::set<std::string> kOtherStatuses = {"failed", "skipped", "not_run"};
/// A session's figures: null unless it ran.
const char* const kFigures[] = {"frames",   "lost_frames",        "keyframes", "keyframes_loaded",
                                "ate_rmse", "tracking_ms_median", "map_report"};

std::string one_of(const std::set<std::string>& a, const std::set<std::string>& b = {}) {
  std::string out;
  for (const auto* set : {&a, &b})
    for (const std::string& s : *set) out += (out.empty() ? "" : ", ") + s;
  return out;
}

/// "status": a run's status or why there is none (version 1: null when it failed).
std::string read_status(const JsonFields& f, const YAML::Node& s, int version) {
  if (version == 1 && JsonFields::absent(s, "status")) return "failed";
  const std::string status = f.text(s, "status");
  if (!kRunStatuses.count(status) && (version == 1 || !kOtherStatuses.count(status)))
    f.fail(s["status"], "status",
           "one of " + (version == 1 ? one_of(kRunStatuses) : one_of(kRunStatuses, kOtherStatuses)), status);
  return status;
}

/// "map_report.localisation": the shares within (0.05 m, 1 deg) and (0.25 m,
/// 2 deg), wrong-place poses and the first pose.
void read_localisation(const JsonFields& f, const YAML::Node& s, CampaignSessionMetrics* m) {
  const YAML::Node report = s["map_report"];
  if (JsonFields::absent(s, "map_report")) return;
  if (!report.IsMap()) f.fail(report, "map_report", "an object or null");
  const YAML::Node l = report["localisation"];
  if (JsonFields::absent(report, "localisation")) return;
  const JsonFields lf = f.nested("map_report.localisation.");
  if (!l.IsMap()) f.fail(l, "map_report.localisation", "an object or null");
  const int frames = lf.integer(l, "frames", 0);
  const YAML::Node within = lf.required(l, "within");
  if (!within.IsMap()) lf.fail(within, "within", "an object");
  for (const char* k : {"fine", "high"}) {
    const YAML::Node c = lf.nested("within.").required(within, k);
    if (!c.IsMap()) lf.fail(c, std::string("within.") + k, "an object");
    (k[0] == 'f' ? m->share_fine : m->share_high) =
        lf.nested(std::string("within.") + k + ".").share(c, "share");
  }
  m->wrong_place = lf.integer(l, "wrong_place", 0, frames, "map_report.localisation.frames");
  if (!JsonFields::absent(l, "first_pose_frame"))
    m->first_pose_frame = lf.integer(l, "first_pose_frame", 0, m->frames.value_or(0) - 1LL, "frames - 1");
}

CampaignSessionMetrics read_session(const JsonFields& f, const YAML::Node& s, int version) {
  if (!s.IsMap()) f.fail(s, "", "an object");
  CampaignSessionMetrics m;
  m.name = f.text(s, "name");
  m.mode = f.text(s, "mode");
  if (m.mode != "map" && m.mode != "localise" && m.mode != "extend")
    f.fail(s["mode"], "mode", "one of map, localise, extend", m.mode);
  m.map = JsonFields::absent(s, "map") ? "" : f.text(s, "map");
  m.status = read_status(f, s, version);
  m.error = JsonFields::absent(s, "error") ? "" : f.text(s, "error");
  const bool ran = kRunStatuses.count(m.status) > 0;
  if (ran || version >= 2) m.seed = f.seed(s, "seed");
  if (!ran) {
    // Version 2 has no figures for a session that did not run (version 1
    // wrote zeros, which are not figures either).
    if (version >= 2)
      for (const char* key : kFigures)
        if (!JsonFields::absent(s, key))
          f.fail(s[key], key,
                 "null for a session that did not run (" + m.status + ")", JsonFields::shown(s[key]));
    return m;
  }
  m.frames = f.integer(s, "frames", 0);
  m.lost_frames = f.integer(s, "lost_frames", 0, *m.frames, "frames");
  m.keyframes = f.integer(s, "keyframes", 0);
  m.keyframes_loaded = f.integer(s, "keyframes_loaded", 0);
  if (!JsonFields::absent(s, "ate_rmse")) f.number(s, "ate_rmse", 0.0);
  if (!JsonFields::absent(s, "tracking_ms_median"))
    m.tracking_ms_median = f.number(s, "tracking_ms_median", 0.0);
  // Version 1 wrote 0 for a session without a tracked frame.
  if (version == 1 && *m.frames == 0) m.tracking_ms_median.reset();
  read_localisation(f, s, &m);
  return m;
}

/// The file itself: its version, campaign, seed and sessions.
void read_campaign_file(const std::string& path, CampaignSeed* c) {
  YAML::Node root = detail::load_json_object(path);
  const JsonFields f(path, "");
  c->version = f.integer(root, "campaign_version", 1, kCampaignVersionRead);
  c->campaign = f.text(root, "campaign");
  if (!JsonFields::absent(root, "seed")) c->file_seed = f.seed(root, "seed");
  const YAML::Node sessions = f.required(root, "sessions");
  if (!sessions.IsSequence()) f.fail(sessions, "sessions", "a list");
  for (std::size_t i = 0; i < sessions.size(); ++i)
    c->sessions.push_back(
        read_session(f.nested("sessions[" + std::to_string(i) + "]."), sessions[i], c->version));
}

/// Half-width of the 95 % interval of the mean (Student's t).
double ci95(const Summary& s) {
  return s.count > 1 ? student_t_quantile(0.975, s.count - 1) * s.sd / std::sqrt(double(s.count)) : 0.0;
}

std::string pct(const Summary& s, double ci) {
  if (s.count == 0) return "-";
  return format_fixed(100 * s.mean, 1) + " ± " + format_fixed(100 * ci, 1) + " % (min " +
         format_fixed(100 * s.min, 1) + " %)";
}

std::string mean_or_dash(const Summary& s, int decimals) {
  return s.count ? format_fixed(s.mean, decimals) : std::string("-");
}

std::string campaign_summary_json(const Summary& s) {
  return "{\"count\": " + std::to_string(s.count) + ", \"mean\": " + json_number(s.mean) +
         ", \"sd\": " + json_number(s.sd) + ", \"min\": " + json_number(s.min) + ", \"max\": " + json_number(s.max) + "}";
}

/// Session i over the seeds that have a campaign.json.
CampaignSessionAggregate aggregate_session(const ExpectedCampaign::Session& e, std::size_t i,
                                           const std::vector<CampaignSeed>& seeds) {
  CampaignSessionAggregate g;
  g.name = e.name, g.mode = e.mode, g.map = e.map;
  std::vector<double> fine, high, first, added, ms;
  for (const CampaignSeed& s : seeds) {
    if (!s.error.empty()) continue;
    ++g.seeds;
    if (i >= s.sessions.size()) {  // a version 1 file of a stopped campaign
      ++g.failed;
      continue;
    }
    const CampaignSessionMetrics& m = s.sessions[i];
    if (!m.completed()) ++g.failed;
    if (m.share_fine) fine.push_back(*m.share_fine);
    if (m.share_high) high.push_back(*m.share_high);
    g.wrong_place += m.wrong_place.value_or(0);
    if (m.first_pose_frame)
      first.push_back(*m.first_pose_frame);
    else if (m.share_fine)
      ++g.never_posed;
    if (m.completed() && m.keyframes && m.keyframes_loaded)
      added.push_back(*m.keyframes - *m.keyframes_loaded);
    if (m.tracking_ms_median) ms.push_back(*m.tracking_ms_median);
  }
  g.fine = summarize(fine), g.high = summarize(high), g.first_pose_frame = summarize(first);
  g.keyframes_added = summarize(added), g.tracking_ms_median = summarize(ms);
  g.fine_ci95 = ci95(g.fine), g.high_ci95 = ci95(g.high);
  return g;
}

}  // namespace

CampaignSeed read_campaign_seed(std::uint64_t seed, const std::string& path) {
  CampaignSeed c;
  c.seed = seed;
  c.path = path;
  struct stat st {};
  const std::string folder = std::filesystem::path(path).parent_path().string();
  if (::stat(path.c_str(), &st) != 0 && errno == ENOENT) {
    c.error = ::stat(folder.c_str(), &st) != 0 ? folder + ": missing (no folder for this seed)"
                                               : path + ": missing";
    return c;
  }
  try {
    read_campaign_file(path, &c);
  } catch (const Error& e) {
    c.error = e.what();
    c.sessions.clear();
  }
  return c;
}

void expect_campaign_identity(const CampaignSeed& c, const ExpectedCampaign& e) {
  if (c.campaign != e.name)
    throw ConfigError(c.path, "campaign", "a run of " + e.name + " (" + e.file + ")",
                      c.campaign.empty() ? std::string("no campaign name") : c.campaign);
  const std::string folder = "the folder seed_" + std::to_string(c.seed);
  if (c.file_seed != c.seed)
    throw ConfigError(c.path, "seed", std::to_string(c.seed) + " (" + folder + ")",
                      c.file_seed ? std::to_string(*c.file_seed) : std::string("no seed"));
  const std::size_t n = c.sessions.size(), want = e.sessions.size();
  if (n > want || (n < want && c.version >= 2))
    throw ConfigError(c.path, "sessions", std::to_string(want) + " sessions (those of " + e.file + ")",
                      std::to_string(n));
  for (std::size_t i = 0; i < n; ++i) {
    const CampaignSessionMetrics& m = c.sessions[i];
    const ExpectedCampaign::Session& x = e.sessions[i];
    const std::string key = "sessions[" + std::to_string(i) + "].";
    const std::string source = " (session " + std::to_string(i + 1) + " of " + e.file + ")";
    if (m.name != x.name) throw ConfigError(c.path, key + "name", x.name + source, m.name);
    if (m.mode != x.mode) throw ConfigError(c.path, key + "mode", x.mode + source, m.mode);
    if (m.map != x.map)
      throw ConfigError(c.path, key + "map", (x.map.empty() ? "no map" : x.map) + source,
                        m.map.empty() ? "no map" : m.map);
    const std::uint64_t seed = c.seed * 1000 + i;
    if (m.seed && *m.seed != seed)
      throw ConfigError(c.path, key + "seed",
                        std::to_string(seed) + " (" + folder + " x 1000 + " + std::to_string(i) + ")",
                        std::to_string(*m.seed));
  }
}

CampaignAggregate aggregate_campaign(const ExpectedCampaign& campaign,
                                     const std::vector<CampaignSeed>& seeds) {
  CampaignAggregate a;
  a.campaign = campaign.name;
  for (const CampaignSeed& s : seeds) {
    a.seeds.push_back(s.seed);
    if (!s.error.empty()) a.seed_errors.push_back("seed " + std::to_string(s.seed) + ": " + s.error);
  }
  for (std::size_t i = 0; i < campaign.sessions.size(); ++i)
    a.sessions.push_back(aggregate_session(campaign.sessions[i], i, seeds));
  return a;
}

std::string format_campaign_markdown(const CampaignAggregate& a) {
  std::string out = "# Campaign " + a.campaign + " over " + std::to_string(a.seeds.size()) + " seeds\n\n";
  out += "| session | mode | map | seeds (failed) | within 0.05 m/1 deg | within 0.25 m/2 deg | wrong place (all seeds) "
         "| first pose frame (median of mean, max) | keyframes added (mean) | tracking ms median (mean) |\n";
  out += "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& g : a.sessions) {
    const std::string first = g.first_pose_frame.count
                                  ? format_fixed(g.first_pose_frame.mean, 1) + ", max " +
                                        format_fixed(g.first_pose_frame.max, 0)
                                  : "-";
    out += "| " + g.name + " | " + g.mode + " | " + (g.map.empty() ? "-" : g.map) + " | " +
           std::to_string(g.seeds) + " (" + std::to_string(g.failed) + ") | " + pct(g.fine, g.fine_ci95) +
           " | " + pct(g.high, g.high_ci95) + " | " + (g.fine.count ? std::to_string(g.wrong_place) : "-") +
           " | " + first + (g.never_posed ? " (" + std::to_string(g.never_posed) + " never)" : "") + " | " +
           mean_or_dash(g.keyframes_added, 1) + " | " + mean_or_dash(g.tracking_ms_median, 2) + " |\n";
  }
  out +=
      "\nIntervals: 95 % of the mean over seeds (Student's t); min: the worst seed; failed: the seeds where "
      "the "
      "session did not complete.\n";
  for (const auto& e : a.seed_errors) out += "\n- " + e;
  return out + "\n";
}
std::string format_campaign_json(const CampaignAggregate& a) {
  std::string out = "{\n  \"campaign\": \"" + json_escape(a.campaign) + "\",\n  \"seeds\": [";
  for (std::size_t i = 0; i < a.seeds.size(); ++i) out += (i ? ", " : "") + std::to_string(a.seeds[i]);
  out += "],\n  \"sessions\": [";
  for (std::size_t i = 0; i < a.sessions.size(); ++i) {
    const auto& g = a.sessions[i];
    out += std::string(i ? "," : "") + "\n    {\"name\": \"" + json_escape(g.name) + "\", \"mode\": \"" +
           g.mode + "\", \"seeds\": " + std::to_string(g.seeds) +
           ", \"failed\": " + std::to_string(g.failed) + ", \"fine\": " + campaign_summary_json(g.fine) +
           ", \"fine_ci95\": " + json_number(g.fine_ci95) + ", \"high\": " + campaign_summary_json(g.high) +
           ", \"high_ci95\": " + json_number(g.high_ci95) +
           ", \"wrong_place\": " + std::to_string(g.wrong_place) +
           ", \"first_pose_frame\": " + campaign_summary_json(g.first_pose_frame) +
           ", \"never_posed\": " + std::to_string(g.never_posed) +
           ", \"keyframes_added\": " + campaign_summary_json(g.keyframes_added) + "}";
  }
  return out + "\n  ]\n}\n";
}

}  // namespace pvb::suite
