#include "pvb/campaign/campaign_run.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>

#include "pvb/common/error.hpp"
#include "pvb/common/output_folder.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/run.hpp"

namespace pvb::run {
namespace {

namespace fs = std::filesystem;

std::string map_file(const std::string& out, const std::string& session) {
  return (fs::path(out) / "maps" / (session + ".pvbmap")).string();
}

bool exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

/// The map options of session `i`: where it loads from and saves to.
MapOptions session_map(const CampaignOptions& opt, const CampaignSession& s) {
  MapOptions m;
  if (s.mode != SessionMode::kMap) {
    m.load_path = map_file(opt.out_dir, s.map);
    m.use = s.mode == SessionMode::kLocalise ? MapUse::kLocalise : MapUse::kExtend;
  }
  if (s.mode != SessionMode::kLocalise) m.save_path = map_file(opt.out_dir, s.name);
  return m;
}

SessionStatus session_status(RunStatus s) {
  switch (s) {
    case RunStatus::kCompleted:
      return SessionStatus::kCompleted;
    case RunStatus::kInterrupted:
      return SessionStatus::kInterrupted;
    case RunStatus::kAborted:
      return SessionStatus::kAborted;
    case RunStatus::kFailed:  // never initialised
      return SessionStatus::kFailed;
  }
  return SessionStatus::kFailed;
}

void fill_result(const RunReport& rep, SessionResult* r) {
  const SlamRun& p = rep.primary;
  r->seed = rep.seed;
  r->status = session_status(rep.status);
  r->frames = p.frames;
  r->lost_frames = p.lost_frames;
  r->keyframes = p.keyframes;
  if (p.map && p.map->load) r->keyframes_loaded = p.map->load->keyframes;
  if (p.eval) r->ate_rmse_m = p.eval->ate.rmse;
  std::vector<double> ms;
  for (const auto& f : p.per_frame) ms.push_back(f.tracking_ms);
  if (!ms.empty()) r->tracking_ms_median = percentile(ms, 0.5);
  r->map = p.map;
}

/// Session i before it runs: not run, with the seed it will run with.
SessionResult pending_session(const CampaignOptions& opt, const Campaign& c, std::size_t i) {
  SessionResult r;
  r.session = c.sessions[i];
  r.seed = opt.seed ? *opt.seed * 1000 + i : r.session.scenario_seed;
  return r;
}

void run_session(const CampaignOptions& opt, std::size_t i, SessionResult* result) {
  SessionResult& r = *result;
  const CampaignSession& s = r.session;
  RunOptions o;
  o.scenario_file = s.scenario_file;
  o.out_dir = (fs::path(opt.out_dir) / s.name).string();
  if (opt.seed) o.seed = *opt.seed * 1000 + i;
  o.max_frames = opt.max_frames;
  o.sync = opt.sync;
  o.map_eval = opt.map_eval;
  o.gl = opt.gl;
  o.stop = opt.stop;
  o.start_m = s.start_m;
  o.map = session_map(opt, s);
  if (opt.on_log) o.on_log = [&](const std::string& line) { opt.on_log("[" + s.name + "] " + line); };
  if (!o.map.load_path.empty() && !exists(o.map.load_path)) {
    r.status = SessionStatus::kSkipped;
    r.error = "session " + s.map + " left no map (" + o.map.load_path + ")";
    return;
  }
  try {
    fill_result(run_scenario(o), &r);
  } catch (const Error& e) {
    r.status = SessionStatus::kFailed;
    r.error = e.what();
  }
}

std::string num_or_null(const std::optional<double>& v) { return v ? json_number(*v) : "null"; }

/// A count of the run, null for a session without one.
std::string count_or_null(const SessionResult& r, std::size_t n) {
  return r.ran() ? std::to_string(n) : "null";
}

std::string session_json(const SessionResult& r) {
  const CampaignSession& s = r.session;
  std::string out = "{\"name\": \"" + json_escape(s.name) + "\", \"mode\": \"" + to_string(s.mode) +
                    "\", \"map\": " + (s.map.empty() ? "null" : "\"" + json_escape(s.map) + "\"") +
                    ", \"scenario\": \"" + json_escape(s.scenario_file) +
                    "\", \"start_m\": " + num_or_null(s.start_m) + ", \"seed\": " + std::to_string(r.seed) +
                    ", \"status\": \"" + to_string(r.status) +
                    "\", \"error\": " + (r.error.empty() ? "null" : "\"" + json_escape(r.error) + "\"");
  out += ", \"frames\": " + count_or_null(r, r.frames) +
         ", \"lost_frames\": " + count_or_null(r, r.lost_frames) +
         ", \"keyframes\": " + count_or_null(r, r.keyframes) +
         ", \"keyframes_loaded\": " + count_or_null(r, r.keyframes_loaded) +
         ", \"ate_rmse\": " + num_or_null(r.ate_rmse_m) +
         ", \"tracking_ms_median\": " + num_or_null(r.tracking_ms_median);
  out += ", \"map_report\": " + (r.map ? map_report_json(*r.map) : std::string("null"));
  return out + "}";
}

/// The status cell of campaign.md: the status, and why for a session
/// that failed or was skipped.
std::string status_cell(const CampaignReport& rep, const SessionResult& r) {
  std::string cell = r.status == SessionStatus::kNotRun ? "not run" : to_string(r.status);
  if (!r.error.empty()) cell += ": " + r.error;
  if (r.status == SessionStatus::kNotRun && rep.stopped) cell += " (the campaign was stopped)";
  // One table cell: a '|' in an error message would end it.
  std::string out;
  for (char c : cell) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

/// "P, S, U": matched landmarks on panels and their frames (backsheets,
/// rails: what turns on a tracker), on what stays (ground, posts, walls,
/// shrubs), and unlabelled; "-" when not classified.
std::string landmark_cell(const SessionResult& s) {
  if (!s.map || s.map->matched_landmarks.empty()) return "-";
  int panel = 0, unlabelled = 0, total = 0;
  for (const auto& [name, n] : s.map->matched_landmarks) {
    if (name == "total") total = n;
    else if (name == "panel" || name == "frame") panel += n;
    else if (name == "unlabelled") unlabelled = n;
  }
  return std::to_string(panel) + ", " + std::to_string(total - panel - unlabelled) + ", " + std::to_string(unlabelled);
}

}  // namespace

const char* to_string(SessionStatus s) {
  switch (s) {
    case SessionStatus::kCompleted:
      return "completed";
    case SessionStatus::kInterrupted:
      return "interrupted";
    case SessionStatus::kAborted:
      return "aborted";
    case SessionStatus::kFailed:
      return "failed";
    case SessionStatus::kSkipped:
      return "skipped";
    case SessionStatus::kNotRun:
      return "not_run";
  }
  return "?";
}

bool SessionResult::ran() const {
  return status == SessionStatus::kCompleted || status == SessionStatus::kInterrupted ||
         status == SessionStatus::kAborted;
}

std::string campaign_markdown(const CampaignReport& r) {
  std::string out = "# Campaign " + r.campaign.name + "\n\n";
  if (!r.campaign.description.empty()) out += r.campaign.description + "\n\n";
  out +=
      "| session | mode | map | status | frames | lost | keyframes (loaded) | within 0.05 m/1 deg "
      "| within 0.25 m/2 deg | wrong place | first pose (frame) | tracking ms median "
      "| matched landmarks: panels and frames, static, unlabelled |\n";
  out += "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const SessionResult& s : r.sessions) {
    const bool ran = s.ran();
    const auto* l = s.map && s.map->localisation ? &*s.map->localisation : nullptr;
    const auto pct = [&](std::size_t k) { return l ? format_fixed(100 * l->share_within[k], 1) + " %" : "-"; };
    const auto count = [&](std::size_t n) { return ran ? std::to_string(n) : std::string("-"); };
    out += "| " + s.session.name + " | " + to_string(s.session.mode) + " | " +
           (s.session.map.empty() ? "-" : s.session.map) + " | " + status_cell(r, s) + " | " +
           count(s.frames) + " | " + count(s.lost_frames) + " | " +
           (ran ? std::to_string(s.keyframes) + " (" + std::to_string(s.keyframes_loaded) + ")" : "-") +
           " | " + pct(0) + " | " + pct(1) + " | " + (l ? std::to_string(l->wrong_place) : "-") + " | " +
           (l && l->first_pose_frame ? std::to_string(*l->first_pose_frame) : "-") + " | " +
           (s.tracking_ms_median ? format_fixed(*s.tracking_ms_median, 2) : "-") + " | " + landmark_cell(s) +
           " |\n";
  }
  return out;
}

std::string campaign_html(const CampaignReport& r, const std::string& markdown) {
  std::string out =
      "<!doctype html><html><head><meta charset=\"utf-8\"><title>campaign " + html_escape(r.campaign.name) +
      "</title></head><body style=\"font-family:sans-serif\">\n<pre>" + html_escape(markdown) + "</pre>\n";
  out += "<img src=\"matrix.png\" alt=\"map session x query session\">\n<ul>\n";
  // A link to each session's report; a session that did not run has none.
  for (const SessionResult& s : r.sessions) {
    const std::string name = html_escape(s.session.name);
    out += s.ran() ? "<li><a href=\"" + name + "/index.html\">" + name + "</a> (" + to_string(s.status) +
                         ")</li>\n"
                   : "<li>" + name + ": " + html_escape(status_cell(r, s)) + "</li>\n";
  }
  return out + "</ul></body></html>\n";
}

CampaignReport run_campaign(const CampaignOptions& opt) {
  CampaignReport report;
  report.campaign = load_campaign(opt.campaign_file);
  report.seed = opt.seed;
  prepare_output_folder(opt.out_dir, opt.overwrite, "campaign");
  std::error_code ec;
  fs::create_directories(fs::path(opt.out_dir) / "maps", ec);
  if (ec) throw IoError(opt.out_dir + "/maps", "cannot create the maps folder: " + ec.message());
  // Every session is in the report from the start, not run until it runs.
  for (std::size_t i = 0; i < report.campaign.sessions.size(); ++i)
    report.sessions.push_back(pending_session(opt, report.campaign, i));
  write_file(opt.out_dir + "/campaign.json", campaign_json(report));
  for (std::size_t i = 0; i < report.sessions.size(); ++i) {
    if (opt.stop && opt.stop->load()) {
      report.stopped = true;
      break;
    }
    SessionResult& s = report.sessions[i];
    run_session(opt, i, &s);
    if (!s.error.empty() && opt.on_log)
      opt.on_log("[" + s.session.name + "] " + to_string(s.status) + ": " + s.error);
    // Written after every session: a stopped campaign keeps what it did.
    write_file(opt.out_dir + "/campaign.json", campaign_json(report));
  }
  // A stop during the last session stops the campaign too.
  if (opt.stop && opt.stop->load()) report.stopped = true;
  const std::string md = campaign_markdown(report);
  write_file(opt.out_dir + "/campaign.md", md);
  plot::write_matrix(campaign_matrix(report), opt.out_dir + "/matrix");
  write_file(opt.out_dir + "/index.html", campaign_html(report, md));
  if (opt.on_log) opt.on_log(md);
  return report;
}

std::string campaign_json(const CampaignReport& r) {
  std::string out =
      "{\n  \"campaign_version\": " + std::to_string(kCampaignJsonVersion) + ",\n  \"campaign\": \"" +
      json_escape(r.campaign.name) + "\",\n  \"file\": \"" + json_escape(r.campaign.file) +
      "\",\n  \"seed\": " + (r.seed ? std::to_string(*r.seed) : std::string("null")) + ",\n  \"sessions\": [";
  for (std::size_t i = 0; i < r.sessions.size(); ++i) out += (i ? ",\n    " : "\n    ") + session_json(r.sessions[i]);
  return out + "\n  ]\n}\n";
}

plot::MatrixFigure campaign_matrix(const std::string& title, const std::vector<MatrixSession>& sessions) {
  plot::MatrixFigure m;
  m.title = title;
  m.row_label = "the session whose map is used";
  m.col_label = "query session";
  for (const MatrixSession& s : sessions) {
    if (s.mode != SessionMode::kLocalise) m.rows.push_back(s.name);
    if (s.mode != SessionMode::kMap) m.cols.push_back(s.name);
  }
  m.values.assign(m.rows.size(), std::vector<std::optional<double>>(m.cols.size()));
  for (const MatrixSession& s : sessions) {
    const auto row = std::find(m.rows.begin(), m.rows.end(), s.map);
    const auto col = std::find(m.cols.begin(), m.cols.end(), s.name);
    if (s.share && row != m.rows.end() && col != m.cols.end())
      m.values[row - m.rows.begin()][col - m.cols.begin()] = s.share;
  }
  return m;
}

plot::MatrixFigure campaign_matrix(const CampaignReport& r) {
  std::vector<MatrixSession> sessions;
  for (const CampaignSession& c : r.campaign.sessions) {
    MatrixSession m{c.name, c.mode, c.map, std::nullopt};
    for (const SessionResult& s : r.sessions)
      if (s.session.name == c.name && s.map && s.map->localisation) m.share = s.map->localisation->share_within[1];
    sessions.push_back(m);
  }
  return campaign_matrix("campaign " + r.campaign.name + ": share of frames within 0.25 m and 2 deg", sessions);
}

int campaign_exit_code(const CampaignReport& r) {
  if (r.stopped) return 130;
  for (const SessionResult& s : r.sessions)
    if (s.status != SessionStatus::kCompleted) return 3;
  return 0;
}

}  // namespace pvb::run
