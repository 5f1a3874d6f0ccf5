#include "pvb/report/map_report.hpp"

#include "pvb/common/text.hpp"

namespace pvb::run {

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

bool MapStation::differs_from(const MapStation& o) const {
  return (!name.empty() && !o.name.empty() && name != o.name) || (seed && o.seed && *seed != *o.seed);
}

std::string MapStation::describe() const {
  if (!known()) return "an unknown station";
  const std::string s = seed ? "station seed " + std::to_string(*seed) : "";
  return name.empty() ? s : s.empty() ? name : name + ", " + s;
}

std::string pose_json(const geom::SE3d& T) {
  std::string out = "[";
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) out += (r || c ? ", " : "") + json_number(T.matrix()(r, c));
  return out + "]";
}

std::vector<std::string> map_log_lines(const MapReport& m) {
  std::vector<std::string> lines;
  if (!m.station_warning.empty()) lines.push_back("warning: " + m.station_warning);
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
    if (m.load->wheel_fit_taken) lines.push_back("map's wheel calibration taken over: this run goes on fitting it");
    if (!m.load->wheel_fit_note.empty()) lines.push_back("map's wheel calibration " + m.load->wheel_fit_note);
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
    out += ", \"loaded\": {\"file\": \"" + json_escape(r.loaded_from) +
           "\", \"sessions\": " + std::to_string(l.sessions) +
           ", \"keyframes\": " + std::to_string(l.keyframes) + ", \"points\": " + std::to_string(l.points) +
           ", \"bytes\": " + std::to_string(l.bytes) + ", \"load_ms\": " + json_number(l.load_ms) +
           ", \"wheel_fit\": " +
           (l.wheel_fit_taken             ? std::string("\"taken\"")
            : l.wheel_fit_note.empty() ? std::string("null")
                                       : "\"" + json_escape(l.wheel_fit_note) + "\"") +
           "}, \"relocalisations\": " + std::to_string(r.relocalisations) +
           ", \"merges\": " + std::to_string(r.merges);
  }
  out += ", \"T_world_map\": " + (r.T_world_map ? pose_json(*r.T_world_map) : std::string("null"));
  if (r.save) {
    const slam::MapSaveInfo& s = *r.save;
    out += ", \"saved\": {\"file\": \"" + json_escape(r.saved_to) +
           "\", \"sessions\": " + std::to_string(s.sessions) +
           ", \"keyframes\": " + std::to_string(s.keyframes) + ", \"points\": " + std::to_string(s.points) +
           ", \"bytes\": " + std::to_string(s.bytes) + ", \"bytes_per_keyframe\": " +
           json_number(s.keyframes ? double(s.bytes) / double(s.keyframes) : 0.0) +
           ", \"save_ms\": " + json_number(s.save_ms) +
           ", \"unmerged_keyframes\": " + std::to_string(s.unmerged_keyframes) + "}";
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
