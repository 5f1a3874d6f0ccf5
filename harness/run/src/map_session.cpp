#include "pvb/run/map_session.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::run {
namespace {

std::string num(double v) { return json_number(v); }

/// The ground-truth pose at t_ns: one within 1 ms, or interpolated between
/// two at most 50 ms apart around it (a motion-capture rate unlike the
/// camera's); nullopt otherwise.
std::optional<geom::SE3d> pose_at(const eval::Trajectory& t, std::int64_t t_ns) {
  const auto& p = t.poses;
  const auto it = std::lower_bound(p.begin(), p.end(), t_ns,
                                   [](const geom::StampedPose& a, std::int64_t b_ns) { return a.t_ns < b_ns; });
  if (it != p.end() && std::llabs(it->t_ns - t_ns) <= 1'000'000) return it->T_w_c;
  if (it != p.begin() && std::llabs(std::prev(it)->t_ns - t_ns) <= 1'000'000) return std::prev(it)->T_w_c;
  if (it == p.begin() || it == p.end() || it->t_ns - std::prev(it)->t_ns > 50'000'000) return std::nullopt;
  const auto& a = *std::prev(it);
  const double s = double(t_ns - a.t_ns) / double(it->t_ns - a.t_ns);
  const geom::Quatd q0(a.T_w_c.linear()), q1(it->T_w_c.linear());
  return geom::make_se3(q0.slerp(s, q1), (1 - s) * a.T_w_c.translation() + s * it->T_w_c.translation());
}

std::string pose_json(const geom::SE3d& T) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out += (r || c ? ", " : "") + num(T.matrix()(r, c));
  return out + "]";
}

}  // namespace

const char* to_string(MapUse u) {
  switch (u) {
    case MapUse::kFresh:
      return "fresh";
    case MapUse::kLocalise:
      return "localise";
    case MapUse::kExtend:
      return "extend";
  }
  return "?";
}

MapUse parse_map_use(const std::string& text, const std::string& option) {
  if (text == "localise") return MapUse::kLocalise;
  if (text == "extend") return MapUse::kExtend;
  throw ConfigError("command line", option, "localise or extend", text);
}

void MapOptions::check() const {
  if (!load_path.empty() && use == MapUse::kFresh)
    throw ConfigError("command line", "--map-mode", "localise or extend with --map");
  if (load_path.empty() && use != MapUse::kFresh)
    throw ConfigError("command line", "--map",
                      "the saved map to " + std::string(to_string(use)) + " (--map-mode needs it)");
  if (use == MapUse::kLocalise && !save_path.empty())
    throw ConfigError("command line", "--save-map",
                      "a map made or extended by the run, not with --map-mode localise");
}

std::string map_app_json(const std::string& scenario, std::uint64_t station_seed,
                         const std::optional<geom::SE3d>& T_world_map, const std::string& scenario_file) {
  return "{\"scenario\": \"" + json_escape(scenario) + "\", \"scenario_file\": " +
         (scenario_file.empty() ? std::string("null") : "\"" + json_escape(scenario_file) + "\"") +
         ", \"station_seed\": " + std::to_string(station_seed) +
         ", \"T_world_map\": " + (T_world_map ? pose_json(*T_world_map) : std::string("null")) + "}";
}

std::string map_scenario_file(const std::string& app_json) {
  const std::string key = "\"scenario_file\": \"";
  const std::size_t at = app_json.find(key);
  if (at == std::string::npos) return "";
  const std::size_t end = app_json.find('"', at + key.size());
  const std::string file = app_json.substr(at + key.size(), end == std::string::npos ? 0 : end - at - key.size());
  return file.find('\\') == std::string::npos ? file : "";  // an escaped name is not read back
}

std::optional<geom::SE3d> T_world_map_of(const std::string& app_json) {
  const std::string key = "\"T_world_map\": [";
  const std::size_t at = app_json.find(key);
  if (at == std::string::npos) return std::nullopt;
  const char* p = app_json.c_str() + at + key.size();
  Eigen::Matrix<double, 3, 4> m;
  for (int k = 0; k < 12; ++k) {
    char* end = nullptr;
    const double v = std::strtod(p, &end);
    if (end == p || !std::isfinite(v)) return std::nullopt;
    m(k / 4, k % 4) = v;
    p = end;
    while (*p == ',' || *p == ' ') ++p;
  }
  const Eigen::Matrix3d R = m.leftCols<3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6) return std::nullopt;
  return geom::make_se3(R, m.col(3));
}

eval::Trajectory ground_truth_at(const eval::Trajectory& gt, const std::vector<std::int64_t>& t_ns) {
  eval::Trajectory out;
  out.source = gt.source;
  for (std::int64_t t : t_ns)
    if (const auto T = pose_at(gt, t); T && (out.poses.empty() || t > out.poses.back().t_ns)) out.poses.push_back({t, *T});
  return out;
}

std::optional<geom::SE3d> T_world_new_map(const eval::Trajectory& gt, const eval::Trajectory& est) {
  for (const auto& p : est.poses)
    if (const auto T_world_c = pose_at(gt, p.t_ns)) return *T_world_c * p.T_w_c.inverse();
  return std::nullopt;
}

MapReport start_map(slam::System& system, const MapOptions& options) {
  options.check();
  MapReport r;
  r.use = options.use;
  if (options.load_path.empty()) return r;
  r.loaded_from = options.load_path;
  r.load = system.load_map(options.load_path, options.use == MapUse::kLocalise ? slam::MapStart::kLocalise
                                                                               : slam::MapStart::kExtend);
  r.T_world_map = T_world_map_of(r.load->app_json);
  for (const auto& l : system.landmark_uses()) r.found_at_load[l.id] = l.found;
  return r;
}

void score_map_localisation(MapReport* r, const eval::Trajectory& gt, const eval::Trajectory& est) {
  if (!r->load) return;
  if (gt.empty()) {
    r->localisation_note = "no ground truth";
  } else if (!r->T_world_map) {
    r->localisation_note = "the map does not say where its frame lies in the world (no T_world_map)";
  } else {
    r->localisation = eval::score_localisation(gt, est, *r->T_world_map);
  }
}

void save_map(slam::System& system, const MapOptions& options, const std::string& scenario,
              std::uint64_t station_seed, MapReport* r, const std::string& scenario_file) {
  if (options.save_path.empty()) return;
  r->saved_to = options.save_path;
  if (system.num_keyframes() == 0) {
    r->save_note = "not saved: the run made no keyframe";
    return;
  }
  // An extended map keeps the scenario it was first made from.
  const std::string made_from = r->load ? map_scenario_file(r->load->app_json) : scenario_file;
  r->save = system.save_map(options.save_path, map_app_json(scenario, station_seed, r->T_world_map, made_from));
}

void finish_map(slam::System& system, const MapOptions& options, const eval::Trajectory& gt,
                const eval::Trajectory& est, const std::string& name, std::uint64_t station_seed, MapReport* r,
                const std::string& scenario_file) {
  r->relocalisations = system.relocalisations().size();
  for (const auto& e : system.loop_stats().loops) r->merges += e.merge ? 1 : 0;
  score_map_localisation(r, gt, est);
  if (!r->load && !gt.empty()) r->T_world_map = T_world_new_map(gt, est);
  save_map(system, options, name, station_seed, r, scenario_file);
}

std::vector<std::string> map_log_lines(const MapReport& m) {
  std::vector<std::string> lines;
  if (m.load) {
    std::string line = "map " + m.loaded_from + " (" + to_string(m.use) + ", " + std::to_string(m.load->keyframes) +
                       " keyframes, loaded in " + format_fixed(m.load->load_ms, 0) + " ms): ";
    if (m.localisation) {
      const eval::LocalisationScores& l = *m.localisation;
      const auto& classes = eval::precision_classes();
      for (std::size_t k = 0; k < classes.size(); ++k)
        line += format_fixed(100 * l.share_within[k], 1) + " % within " + format_g(classes[k].max_translation_m) +
                " m/" + format_g(classes[k].max_rotation_deg) + " deg, ";
      line += std::to_string(l.wrong_place) + " wrong-place poses, first pose at frame " +
              (l.first_pose_frame ? std::to_string(*l.first_pose_frame) : std::string("-"));
      if (m.merges) line += ", " + std::to_string(m.merges) + " provisional map(s) merged";
    } else {
      line += "not scored: " + m.localisation_note;
    }
    lines.push_back(line);
  }
  if (!m.save_note.empty()) lines.push_back("map " + m.saved_to + " " + m.save_note);
  if (m.save)
    lines.push_back("map saved to " + m.saved_to + ": " + std::to_string(m.save->sessions) + " sessions, " +
                    std::to_string(m.save->keyframes) + " keyframes, " + std::to_string(m.save->points) +
                    " points, " + std::to_string(m.save->bytes) + " bytes in " + format_fixed(m.save->save_ms, 0) +
                    " ms" +
                    (m.save->unmerged_keyframes
                         ? "; " + std::to_string(m.save->unmerged_keyframes) +
                               " keyframes of a provisional map never merged were left out"
                         : std::string()));
  return lines;
}

std::string map_report_json(const MapReport& r) {
  std::string out = "{\"use\": \"" + std::string(to_string(r.use)) + "\"";
  if (r.load) {
    const slam::MapLoadInfo& l = *r.load;
    out += ", \"loaded\": {\"file\": \"" + json_escape(r.loaded_from) + "\", \"sessions\": " +
           std::to_string(l.sessions) + ", \"keyframes\": " + std::to_string(l.keyframes) +
           ", \"points\": " + std::to_string(l.points) + ", \"bytes\": " + std::to_string(l.bytes) +
           ", \"load_ms\": " + num(l.load_ms) + "}, \"relocalisations\": " + std::to_string(r.relocalisations) +
           ", \"merges\": " + std::to_string(r.merges);
  }
  out += ", \"T_world_map\": " + (r.T_world_map ? pose_json(*r.T_world_map) : std::string("null"));
  if (r.save) {
    const slam::MapSaveInfo& s = *r.save;
    out += ", \"saved\": {\"file\": \"" + json_escape(r.saved_to) + "\", \"sessions\": " +
           std::to_string(s.sessions) + ", \"keyframes\": " + std::to_string(s.keyframes) +
           ", \"points\": " + std::to_string(s.points) + ", \"bytes\": " + std::to_string(s.bytes) +
           ", \"bytes_per_keyframe\": " + num(s.keyframes ? double(s.bytes) / double(s.keyframes) : 0.0) +
           ", \"save_ms\": " + num(s.save_ms) + ", \"unmerged_keyframes\": " + std::to_string(s.unmerged_keyframes) +
           "}";
  }
  if (!r.save_note.empty()) out += ", \"save_note\": \"" + json_escape(r.save_note) + "\"";
  if (!r.matched_landmarks.empty()) {
    out += ", \"matched_landmarks\": {";
    for (std::size_t i = 0; i < r.matched_landmarks.size(); ++i)
      out += (i ? ", \"" : "\"") + r.matched_landmarks[i].first + "\": " + std::to_string(r.matched_landmarks[i].second);
    out += "}";
  } else if (!r.matched_landmarks_note.empty()) {
    out += ", \"matched_landmarks_note\": \"" + json_escape(r.matched_landmarks_note) + "\"";
  }
  if (r.load)
    out += ", \"localisation\": " +
           (r.localisation ? eval::localisation_json(*r.localisation)
                           : "null, \"localisation_note\": \"" + json_escape(r.localisation_note) + "\"");
  return out + "}";
}

}  // namespace pvb::run
