#include "pvb/suite/metrics_file.hpp"

#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <climits>
#include <cmath>

#include "json_fields.hpp"
#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/common/yaml_reader.hpp"
#include "pvb/eval/slam_mode.hpp"

namespace pvb::suite {
namespace {

// Reads one metrics object; `prefix` names nested keys in errors ("baseline.").
class Reader : public detail::JsonFields {
 public:
  using JsonFields::JsonFields;

  /// An optional number >= 0 under obj[key][sub] (absent or null object -> nullopt).
  std::optional<double> optional_number(const YAML::Node& obj, const std::string& key,
                                        const std::string& sub) const {
    const YAML::Node n = obj[key];
    if (!n.IsDefined() || n.IsNull()) return std::nullopt;
    if (!n.IsMap()) fail(n, key, "an object or null");
    return nested(key + ".").number(n, sub, 0.0);
  }

  /// "ate"/"rpe" must be present, and an object or null; the RMSE is >= 0.
  std::optional<double> stats_rmse(const YAML::Node& obj, const std::string& key,
                                   const std::vector<std::string>& path) const {
    YAML::Node n = required(obj, key);
    if (n.IsNull()) return std::nullopt;
    std::string name = key;
    for (const auto& p : path) {
      if (!n.IsMap()) fail(n, name, "an object or null");
      const YAML::Node child = n[p];
      if (!child.IsDefined()) missing(n, name + "." + p);
      n = child;
      name += "." + p;
    }
    if (!n.IsMap()) fail(n, name, "an object");
    return nested(name + ".").number(n, "rmse", 0.0);
  }

  /// "loss_events": each loss's frame, time and recovery (not before the loss).
  std::vector<LossEvent> loss_events(const YAML::Node& obj) const {
    const YAML::Node events = obj["loss_events"];
    if (!events.IsDefined() || events.IsNull()) return {};
    if (!events.IsSequence()) fail(events, "loss_events", "a list");
    std::vector<LossEvent> out;
    for (std::size_t i = 0; i < events.size(); ++i) {
      const Reader inner(path(), prefix() + "loss_events[" + std::to_string(i) + "].");
      if (!events[i].IsMap()) inner.fail(events[i], "", "an object");
      LossEvent e;
      e.frame = inner.integer(events[i], "frame", 0);
      if (events[i]["t_s"].IsDefined()) e.t_s = inner.number(events[i], "t_s", 0.0);
      const YAML::Node reason = events[i]["reason"];
      if (reason.IsDefined() && !reason.IsNull()) e.reason = inner.text(events[i], "reason");
      const YAML::Node rec = events[i]["recovered_frame"];
      if (rec.IsDefined() && !rec.IsNull())
        e.recovered_frame = inner.integer(events[i], "recovered_frame", e.frame, INT_MAX, "frame");
      out.push_back(e);
    }
    return out;
  }

  RunMetrics run(const YAML::Node& obj) const {
    if (!obj.IsMap()) fail(obj, "(top level)", "a JSON object");
    RunMetrics r;
    if (obj["mode"].IsDefined()) r.mode = eval::normalized_mode(text(obj, "mode"));
    if (obj["sensors"].IsDefined()) r.sensors = text(obj, "sensors");
    r.status = text(obj, "status");
    if (r.status != "completed" && r.status != "interrupted" && r.status != "aborted" && r.status != "failed")
      fail(obj["status"], "status", "completed, interrupted, aborted or failed", r.status);
    r.frames = integer(obj, "frames", 0);
    r.lost_frames = integer(obj, "lost_frames", 0, r.frames, "frames");
    if (!absent(obj, "keyframes")) r.keyframes = integer(obj, "keyframes", 0);
    r.ate_rmse_m = stats_rmse(obj, "ate", {});
    r.rpe_trans_rmse_m = stats_rmse(obj, "rpe", {"trans"});
    r.tracking_ms_median = optional_number(obj, "tracking_ms", "median");
    if (!absent(obj, "realtime_factor")) r.realtime_factor = number(obj, "realtime_factor", 0.0);
    r.loss_events = loss_events(obj);
    r.refined_ate_rmse_m = optional_number(obj, "refined", "ate_rmse");
    r.place = place(obj);
    r.maps = maps(obj);
    r.blind = blind(obj);
    const YAML::Node cover = obj["camera_covered_frames"];
    if (cover.IsDefined() && !cover.IsNull()) {
      if (!cover.IsSequence() || cover.size() != 2) fail(cover, "camera_covered_frames", "[first, last]");
      const int first = integer_at(cover[0], "camera_covered_frames[0]", 0);
      r.camera_covered_frames = {first,
                                 integer_at(cover[1], "camera_covered_frames[1]", first, INT_MAX, "first")};
    }
    return r;
  }

  /// "blind": the covered frames, their poses and the first frame after them.
  std::optional<BlindMetrics> blind(const YAML::Node& obj) const {
    const YAML::Node n = obj["blind"];
    if (!n.IsDefined() || n.IsNull()) return std::nullopt;
    if (!n.IsMap()) fail(n, "blind", "an object or null");
    const JsonFields in = nested("blind.");
    BlindMetrics b;
    const YAML::Node cover = in.required(n, "covered_frames");
    if (!cover.IsSequence() || cover.size() != 2) in.fail(cover, "covered_frames", "[first, last]");
    b.first_covered = in.integer_at(cover[0], "covered_frames[0]", 0);
    b.last_covered = in.integer_at(cover[1], "covered_frames[1]", b.first_covered, INT_MAX, "first");
    b.covered_with_pose =
        in.integer(n, "covered_frames_with_pose", 0, b.covered_frames(), "the covered frames");
    b.relocalised_frames = in.integer(n, "relocalised_frames", 0);
    if (!absent(n, "first_after_frame")) b.first_after = in.integer(n, "first_after_frame", 0);
    b.first_after_tracked = boolean(in, n, "first_after_tracked");
    if (!absent(n, "first_after_method")) b.first_after_method = in.text(n, "first_after_method");
    if (!absent(n, "first_after_state")) b.first_after_state = in.text(n, "first_after_state");
    const YAML::Node err = n["first_after_error"];
    if (err.IsDefined() && !err.IsNull()) {
      if (!err.IsMap()) in.fail(err, "first_after_error", "an object or null");
      const JsonFields e = in.nested("first_after_error.");
      b.first_after_error_m = e.number(err, "trans_m", 0.0);
      b.first_after_error_deg = e.number(err, "rot_deg", 0.0, 180.0);
    }
    return b;
  }

  /// true or false under obj[key] (required).
  static bool boolean(const JsonFields& in, const YAML::Node& obj, const std::string& key) {
    const YAML::Node v = in.required(obj, key);
    if (!is_plain_scalar(v) || (v.Scalar() != "true" && v.Scalar() != "false"))
      in.fail(v, key, "true or false", shown(v));
    return v.Scalar() == "true";
  }

  /// "dense_map.maps": each map's whole-map scores (tau 1, 2, 5, 10 cm).
  std::vector<MapMetrics> maps(const YAML::Node& obj) const {
    const YAML::Node d = obj["dense_map"];
    if (!d.IsDefined() || d.IsNull()) return {};
    if (!d.IsMap()) fail(d, "dense_map", "an object or null");
    const YAML::Node maps = d["maps"];
    if (!maps.IsDefined()) return {};
    if (!maps.IsMap()) fail(maps, "dense_map.maps", "an object");
    std::vector<MapMetrics> out;
    for (const auto& kv : maps) {
      const std::string name = kv.first.Scalar();
      const JsonFields in = nested("dense_map.maps." + name + ".");
      const YAML::Node all = in.required(kv.second, "all");
      const JsonFields all_in = in.nested("all.");
      const YAML::Node comp = all_in.required(all, "completeness_at");
      if (!comp.IsSequence() || comp.size() < 3) all_in.fail(comp, "completeness_at", "4 shares (1, 2, 5, 10 cm)");
      MapMetrics m;
      m.name = name;
      const YAML::Node acc = all_in.required(all, "accuracy_m");
      if (!acc.IsNull()) m.accuracy_median_m = all_in.nested("accuracy_m.").number(acc, "median", 0.0);
      const auto share = [&](std::size_t i) {
        return all_in.number_at(comp[i], "completeness_at[" + std::to_string(i) + "]", 0.0, 1.0);
      };
      m.completeness_2cm = share(1);
      m.completeness_5cm = share(2);
      m.ghosting = all_in.share(all, "ghosting");
      out.push_back(m);
    }
    return out;
  }

  /// "place_recognition": counts always, labels when judged against ground truth.
  std::optional<PlaceMetrics> place(const YAML::Node& obj) const {
    const YAML::Node n = obj["place_recognition"];
    if (!n.IsDefined() || n.IsNull()) return std::nullopt;
    if (!n.IsMap()) fail(n, "place_recognition", "an object or null");
    const JsonFields in = nested("place_recognition.");
    PlaceMetrics p;
    p.loops_proposed = in.integer(n, "loops_proposed", 0);
    p.loops_accepted = in.integer(n, "loops_accepted", 0);
    p.relocalisations = in.integer(n, "relocalisations", 0);
    const auto opt = [&](const char* key, std::optional<int>* v) {
      if (n[key].IsDefined()) *v = in.integer(n, key, 0);
    };
    opt("loops_true", &p.loops_true);
    opt("loops_false", &p.loops_false);
    opt("loops_missed", &p.loops_missed);
    opt("revisits", &p.revisits);
    opt("relocalisations_true", &p.relocalisations_true);
    opt("relocalisations_false", &p.relocalisations_false);
    return p;
  }
};

/// The station of a day's run, from "world" (informative: left unread when
/// its shape is not the expected one).
void read_station(const YAML::Node& world, MetricsFile* m) {
  if (!world.IsMap()) return;
  const YAML::Node seed = world["station_seed"], files = world["base_files"];
  unsigned long long v = 0;
  if (seed.IsDefined() && Reader::is_plain_scalar(seed) && YAML::convert<unsigned long long>::decode(seed, v))
    m->station_seed = v;
  if (files.IsSequence() && files.size() > 0 && files[0].IsScalar()) m->station_file = files[0].Scalar();
}

}  // namespace

const MapMetrics* RunMetrics::map(const std::string& name) const {
  for (const MapMetrics& m : maps)
    if (m.name == name) return &m;
  return nullptr;
}

MetricsFile read_metrics_file(const std::string& path) {
  YAML::Node root = detail::load_json_object(path);
  MetricsFile m;
  m.path = path;
  const Reader top(path, "");
  // Version 1 files have no metrics_version; a newer version than this
  // program knows is refused rather than read as if it were this one.
  const YAML::Node version = root["metrics_version"];
  if (version.IsDefined()) {
    const int v = top.integer(root, "metrics_version");
    if (v < 1 || v > eval::kMetricsVersion)
      top.fail(version, "metrics_version",
               "1 to " + std::to_string(eval::kMetricsVersion) + " (this pvbench reads up to version " +
                   std::to_string(eval::kMetricsVersion) + ")",
               std::to_string(v));
    m.version = v;
  }
  if (root["scenario"].IsDefined()) m.scenario = top.text(root, "scenario");
  if (!Reader::absent(root, "seed")) m.seed = top.seed(root, "seed");
  read_station(root["world"], &m);
  m.primary = top.run(root);
  const YAML::Node base = root["baseline"];
  if (base.IsDefined() && !base.IsNull()) {
    if (!base.IsMap()) top.fail(base, "baseline", "an object");
    m.baseline = Reader(path, "baseline.").run(base);
  }
  return m;
}

void expect_run_identity(const MetricsFile& m, const std::string& scenario, const std::string& scenario_source,
                         std::optional<unsigned long long> seed, const std::string& seed_source) {
  if (!scenario.empty() && m.scenario != scenario)
    throw ConfigError(m.path, "scenario",
                      "a run of " + scenario + (scenario_source.empty() ? "" : " (" + scenario_source + ")"),
                      m.scenario.empty() ? std::string("no scenario name") : m.scenario);
  if (seed && m.seed != seed)
    throw ConfigError(m.path, "seed",
                      std::to_string(*seed) + (seed_source.empty() ? "" : " (" + seed_source + ")"),
                      m.seed ? std::to_string(*m.seed) : std::string("no seed"));
}

std::optional<FolderIdentity> read_folder_identity(const std::string& dir) {
  const std::string metrics = dir + "/metrics.json", meta = dir + "/meta.json";
  struct stat st {};
  if (::stat(metrics.c_str(), &st) == 0) {
    const MetricsFile m = read_metrics_file(metrics);
    return FolderIdentity{metrics, m.scenario, m.seed, m.station_seed, m.station_file};
  }
  if (::stat(meta.c_str(), &st) != 0) return std::nullopt;
  const yaml::ReadContext json{meta, nullptr, yaml::ErrorKind::kIo, true};
  YAML::Node root = yaml::parse(read_file(meta), json);
  FolderIdentity id{meta, "", std::nullopt, std::nullopt, ""};
  const YAML::Node name = root.IsMap() && root["scenario"].IsMap() ? root["scenario"]["name"] : YAML::Node();
  if (name.IsDefined() && name.IsScalar()) id.scenario = name.Scalar();
  const YAML::Node seed = root.IsMap() ? root["seed"] : YAML::Node();
  unsigned long long v = 0;
  if (seed.IsDefined() && Reader::is_plain_scalar(seed) && YAML::convert<unsigned long long>::decode(seed, v))
    id.seed = v;
  return id;
}

}  // namespace pvb::suite
