#include "pvb/run/map_session.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/common/yaml_reader.hpp"
#include "pvb/slam/core/map_file.hpp"

namespace pvb::run {
namespace {

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

}  // namespace

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

namespace {

/// The common reader's context for a JSON text pvbench wrote and reads
/// back (a recording's meta.json, a map's META): its mistakes are IoErrors.
yaml::ReadContext json_context(const std::string& file) {
  yaml::ReadContext ctx;
  ctx.file = file;
  ctx.errors = yaml::ErrorKind::kIo;
  ctx.json = true;
  return ctx;
}

/// The name of a station file: "scenes/pv_station.yaml" -> "pv_station".
std::string station_name(const std::string& file) { return std::filesystem::path(file).stem().string(); }

}  // namespace

MapStation station_of(const scenes::Scenario& s) {
  const std::string& file = s.base_files.empty() ? s.source_file : s.base_files.back();
  return MapStation{file.empty() ? std::string() : station_name(file), s.station_seed_or_seed()};
}

MapStation recording_station(const std::string& meta_json_path) {
  MapStation st;
  if (!std::ifstream(meta_json_path).good()) return st;
  const std::string text = read_file(meta_json_path);
  const yaml::ReadContext ctx = json_context(meta_json_path);
  try {
    const YAML::Node root = yaml::parse(text, ctx);
    const YAML::Node world = root["world"], scenario = root["scenario"];
    std::uint64_t seed = 0;
    if (world.IsMap() && world["station_seed"].IsScalar()) {
      if (!yaml::decode_seed(world["station_seed"], ctx, &seed)) return MapStation{};
      st.seed = seed;
    }
    const YAML::Node bases = world.IsMap() ? world["base_files"] : YAML::Node();
    if (bases.IsSequence() && bases.size() > 0 && bases[bases.size() - 1].IsScalar())
      st.name = station_name(bases[bases.size() - 1].Scalar());
    else if (scenario.IsMap() && scenario["file"].IsScalar())
      st.name = station_name(scenario["file"].Scalar());
  } catch (const IoError&) {
    return MapStation{};  // informative only: a recording that does not say has no station
  } catch (const YAML::Exception&) {
    return MapStation{};
  }
  return st;
}

std::string map_app_json(const std::string& scenario, const MapStation& station,
                         const std::optional<geom::SE3d>& T_world_map, const std::string& scenario_file) {
  const auto str = [](const std::string& v) {
    return v.empty() ? std::string("null") : "\"" + json_escape(v) + "\"";
  };
  return "{\"scenario\": \"" + json_escape(scenario) + "\", \"scenario_file\": " + str(scenario_file) +
         ", \"station\": " + str(station.name) +
         ", \"station_seed\": " + (station.seed ? std::to_string(*station.seed) : std::string("null")) +
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

namespace {

/// T_world_map of META: null, or 12 finite numbers that make a rotation
/// and a translation within slam::kMaxMapCoordinateM.  `fail` throws.
template <class Fail>
std::optional<geom::SE3d> read_T_world_map(const YAML::Node& v, const yaml::ReadContext& ctx, const Fail& fail) {
  if (!v.IsDefined()) fail("no T_world_map (expected 12 numbers, a 3x4 matrix row by row, or null)");
  if (v.IsNull()) return std::nullopt;
  if (!v.IsSequence() || v.size() != 12)
    fail("T_world_map has " +
         (v.IsSequence() ? std::to_string(v.size()) + " numbers" : std::string("no list")) +
         ", expected 12 (a 3x4 matrix row by row) or null");
  Eigen::Matrix<double, 3, 4> m;
  for (int k = 0; k < 12; ++k) {
    double x = 0;
    if (!yaml::decode_number(v[k], ctx, &x))
      fail("T_world_map number " + std::to_string(k + 1) + " is not a finite number (" +
           printable(v[k].IsScalar() ? v[k].Scalar() : std::string("not a scalar")) + ")");
    m(k / 4, k % 4) = x;
  }
  const Eigen::Matrix3d R = m.leftCols<3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0)
    fail("T_world_map's first three columns are not a rotation");
  if (m.col(3).cwiseAbs().maxCoeff() > slam::kMaxMapCoordinateM)
    fail("T_world_map's translation lies beyond " + format_g(slam::kMaxMapCoordinateM) + " m");
  return geom::make_se3(R, m.col(3));
}

/// META's station: "station" a string or null, "station_seed" a whole
/// number or null (either may be missing: a map made before they were written).
template <class Fail>
MapStation read_station(const YAML::Node& root, const yaml::ReadContext& ctx, const Fail& fail) {
  MapStation st;
  const YAML::Node name = root["station"], seed = root["station_seed"];
  if (name.IsDefined() && !name.IsNull()) {
    if (!name.IsScalar() || name.Scalar().empty()) fail("station is not a name (a string) or null");
    st.name = name.Scalar();
  }
  if (seed.IsDefined() && !seed.IsNull()) {
    std::uint64_t v = 0;
    if (!yaml::decode_seed(seed, ctx, &v))
      fail("station_seed is not a whole number from 0 (" + printable(seed.IsScalar() ? seed.Scalar() : "") + ")");
    st.seed = v;
  }
  return st;
}

/// The common reader's complaint about META's text as META's errors say
/// it: "not JSON (what, line N of the section)", or a key given twice.
std::string meta_problem(const IoError& e) {
  const std::string syntax = "not valid JSON: ";
  const std::string& m = e.message();
  const std::string line = e.line() > 0 ? "line " + std::to_string(e.line()) + " of the section" : "";
  if (m.compare(0, syntax.size(), syntax) == 0)
    return "not JSON (" + m.substr(syntax.size()) + (line.empty() ? "" : ", " + line) + ")";
  return m + (line.empty() ? "" : " (" + line + ")");
}

}  // namespace

MapMeta read_map_meta(const std::string& app_json, const std::string& file) {
  const auto fail = [&](const std::string& what) -> void { throw IoError(file, "META section: " + what); };
  if (app_json.find_first_not_of(" \t\r\n") == std::string::npos) fail("empty, expected a JSON object");
  const yaml::ReadContext ctx = json_context(file);
  YAML::Node root;
  try {
    root = yaml::parse(app_json, ctx);
  } catch (const IoError& e) {
    fail(meta_problem(e));
  }
  // yaml-cpp reads YAML too: a JSON object is one in braces.
  if (!root.IsMap() || app_json[app_json.find_first_not_of(" \t\r\n")] != '{') fail("not a JSON object");
  MapMeta meta;
  meta.T_world_map = read_T_world_map(root["T_world_map"], ctx, fail);
  meta.station = read_station(root, ctx, fail);
  return meta;
}

eval::Trajectory session_keyframes(const eval::Trajectory& written, const slam::System& system) {
  eval::Trajectory out;
  out.source = written.source;
  const std::optional<std::int64_t> first = system.session_first_t_ns();
  if (!first) return out;
  const std::int64_t offset = system.session_clock_offset_ns();
  for (const geom::StampedPose& p : written.poses)
    if (p.t_ns >= *first + offset) out.poses.push_back({p.t_ns - offset, p.T_w_c});
  return out;
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
  const MapMeta meta = read_map_meta(r.load->app_json, options.load_path);
  r.T_world_map = meta.T_world_map;
  r.loaded_station = meta.station;
  if (meta.station.differs_from(options.station)) {
    if (!options.allow_other_station)
      throw ConfigError(options.load_path, "META station",
                        "a map of this run's station, " + options.station.describe() +
                            " (--allow-other-station uses it all the same)",
                        meta.station.describe());
    r.station_warning = "the map " + options.load_path + " shows " + meta.station.describe() +
                        ", this run is on " + options.station.describe();
    std::fprintf(stderr, "pvbench: warning: %s\n", r.station_warning.c_str());
  }
  for (const auto& l : system.landmark_uses()) r.found_at_load[l.id] = l.found;
  return r;
}

void score_map_localisation(MapReport* r, const eval::Trajectory& gt, const eval::Trajectory& est) {
  if (!r->load) return;
  if (gt.empty()) {
    r->localisation_note = "no ground truth";
  } else if (!r->T_world_map) {
    r->localisation_note =
        "the map does not say where its frame lies in the world (T_world_map null: made without ground "
        "truth)";
  } else {
    r->localisation = eval::score_localisation(gt, est, *r->T_world_map);
  }
}

void save_map(slam::System& system, const MapOptions& options, const std::string& scenario, MapReport* r,
              const std::string& scenario_file) {
  if (options.save_path.empty()) return;
  r->saved_to = options.save_path;
  if (system.num_keyframes() == 0) {
    r->save_note = "not saved: the run made no keyframe";
    return;
  }
  // An extended map keeps the scenario it was first made from, and its station.
  const std::string made_from = r->load ? map_scenario_file(r->load->app_json) : scenario_file;
  const MapStation& station = r->load ? r->loaded_station : options.station;
  r->save = system.save_map(options.save_path, map_app_json(scenario, station, r->T_world_map, made_from));
}

void finish_map(slam::System& system, const MapOptions& options, const eval::Trajectory& gt,
                const eval::Trajectory& est, const std::string& name, MapReport* r,
                const std::string& scenario_file) {
  r->relocalisations = system.relocalisations().size();
  for (const auto& e : system.loop_stats().loops) r->merges += e.merge ? 1 : 0;
  score_map_localisation(r, gt, est);
  if (!r->load && !gt.empty()) r->T_world_map = T_world_new_map(gt, est);
  save_map(system, options, name, r, scenario_file);
}

}  // namespace pvb::run
