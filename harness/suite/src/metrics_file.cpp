#include "pvb/suite/metrics_file.hpp"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <sys/stat.h>

#include <climits>
#include <cmath>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/eval/slam_mode.hpp"

namespace pvb::suite {
namespace {

// Reads one metrics object; `prefix` names nested keys in errors ("baseline.").
class Reader {
 public:
  Reader(std::string path, std::string prefix) : path_(std::move(path)), prefix_(std::move(prefix)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
    const YAML::Mark m = at.Mark();
    throw IoError(path_, prefix_ + key + ": " + what, m.line >= 0 ? m.line + 1 : 0);
  }

  YAML::Node required(const YAML::Node& obj, const std::string& key) const {
    const YAML::Node n = obj[key];
    if (!n.IsDefined()) fail(obj, key, "missing");
    return n;
  }

  /// yaml-cpp reads JSON, and would decode the string "0.003" as a number:
  /// a quoted scalar (tag "!") is a string, never a number.
  static bool is_plain_scalar(const YAML::Node& n) { return n.IsScalar() && n.Tag() != "!"; }

  double number(const YAML::Node& obj, const std::string& key) const {
    const YAML::Node n = required(obj, key);
    double v = 0;
    if (!is_plain_scalar(n) || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(n, key, "expected a number, got " + shown(n));
    return v;
  }

  int integer(const YAML::Node& obj, const std::string& key) const {
    const YAML::Node n = required(obj, key);
    long long v = 0;
    if (!is_plain_scalar(n) || !YAML::convert<long long>::decode(n, v) || v < INT_MIN || v > INT_MAX)
      fail(n, key, "expected an integer, got " + shown(n));
    return static_cast<int>(v);
  }

  /// A value as the message shows it: a string in quotes.
  static std::string shown(const YAML::Node& n) {
    if (!n.IsScalar()) return n.IsNull() ? "null" : "a list or an object";
    return n.Tag() == "!" ? "the string \"" + n.Scalar() + "\"" : n.Scalar();
  }

  std::string text(const YAML::Node& obj, const std::string& key) const {
    const YAML::Node n = required(obj, key);
    if (!n.IsScalar()) fail(n, key, "expected a string");
    return n.Scalar();
  }

  /// An optional number under obj[key][sub] (absent or null object -> nullopt).
  std::optional<double> optional_number(const YAML::Node& obj, const std::string& key,
                                        const std::string& sub) const {
    const YAML::Node n = obj[key];
    if (!n.IsDefined() || n.IsNull()) return std::nullopt;
    if (!n.IsMap()) fail(n, key, "expected an object or null");
    const Reader inner(path_, prefix_ + key + ".");
    return inner.number(n, sub);
  }

  /// "ate"/"rpe" must be present, and an object or null.
  std::optional<double> stats_rmse(const YAML::Node& obj, const std::string& key,
                                   const std::vector<std::string>& path) const {
    YAML::Node n = required(obj, key);
    if (n.IsNull()) return std::nullopt;
    std::string name = key;
    for (const auto& p : path) {
      if (!n.IsMap()) fail(n, name, "expected an object or null");
      const YAML::Node child = n[p];
      if (!child.IsDefined()) fail(n, name + "." + p, "missing");
      n = child;
      name += "." + p;
    }
    if (!n.IsMap()) fail(n, name, "expected an object");
    const Reader inner(path_, prefix_ + name + ".");
    return inner.number(n, "rmse");
  }

  RunMetrics run(const YAML::Node& obj) const {
    if (!obj.IsMap()) fail(obj, "(top level)", "expected a JSON object");
    RunMetrics r;
    if (obj["mode"].IsDefined()) r.mode = eval::normalized_mode(text(obj, "mode"));
    r.status = text(obj, "status");
    if (r.status != "completed" && r.status != "interrupted" && r.status != "aborted" && r.status != "failed")
      fail(obj["status"], "status", "expected completed, interrupted, aborted or failed, got " + r.status);
    r.frames = integer(obj, "frames");
    r.lost_frames = integer(obj, "lost_frames");
    if (obj["keyframes"].IsDefined() && !obj["keyframes"].IsNull()) r.keyframes = integer(obj, "keyframes");
    r.ate_rmse_m = stats_rmse(obj, "ate", {});
    r.rpe_trans_rmse_m = stats_rmse(obj, "rpe", {"trans"});
    r.tracking_ms_median = optional_number(obj, "tracking_ms", "median");
    const YAML::Node rtf = obj["realtime_factor"];
    if (rtf.IsDefined() && !rtf.IsNull()) r.realtime_factor = number(obj, "realtime_factor");
    const YAML::Node events = obj["loss_events"];
    if (events.IsDefined() && !events.IsNull()) {
      if (!events.IsSequence()) fail(events, "loss_events", "expected a list");
      for (std::size_t i = 0; i < events.size(); ++i) {
        const Reader inner(path_, prefix_ + "loss_events[" + std::to_string(i) + "].");
        if (!events[i].IsMap()) inner.fail(events[i], "", "expected an object");
        LossEvent e;
        e.frame = inner.integer(events[i], "frame");
        if (events[i]["t_s"].IsDefined()) e.t_s = inner.number(events[i], "t_s");
        const YAML::Node reason = events[i]["reason"];
        if (reason.IsDefined() && !reason.IsNull()) e.reason = inner.text(events[i], "reason");
        const YAML::Node rec = events[i]["recovered_frame"];
        if (rec.IsDefined() && !rec.IsNull()) e.recovered_frame = inner.integer(events[i], "recovered_frame");
        r.loss_events.push_back(e);
      }
    }
    r.refined_ate_rmse_m = optional_number(obj, "refined", "ate_rmse");
    r.place = place(obj);
    r.maps = maps(obj);
    const YAML::Node cover = obj["camera_covered_frames"];
    if (cover.IsDefined() && !cover.IsNull()) {
      if (!cover.IsSequence() || cover.size() != 2) fail(cover, "camera_covered_frames", "expected [first, last]");
      r.camera_covered_frames = {cover[0].as<int>(-1), cover[1].as<int>(-1)};
    }
    return r;
  }

  /// "dense_map.maps": each map's whole-map scores (tau 1, 2, 5, 10 cm).
  std::vector<MapMetrics> maps(const YAML::Node& obj) const {
    const YAML::Node d = obj["dense_map"];
    if (!d.IsDefined() || d.IsNull()) return {};
    if (!d.IsMap()) fail(d, "dense_map", "expected an object or null");
    const YAML::Node maps = d["maps"];
    if (!maps.IsDefined()) return {};
    if (!maps.IsMap()) fail(maps, "dense_map.maps", "expected an object");
    std::vector<MapMetrics> out;
    for (const auto& kv : maps) {
      const std::string name = kv.first.Scalar();
      const Reader in(path_, prefix_ + "dense_map.maps." + name + ".");
      const YAML::Node all = in.required(kv.second, "all");
      const Reader all_in(path_, prefix_ + "dense_map.maps." + name + ".all.");
      const YAML::Node comp = all_in.required(all, "completeness_at");
      if (!comp.IsSequence() || comp.size() < 3) all_in.fail(comp, "completeness_at", "expected 4 shares (1, 2, 5, 10 cm)");
      MapMetrics m;
      m.name = name;
      const YAML::Node acc = all_in.required(all, "accuracy_m");
      if (!acc.IsNull())
        m.accuracy_median_m =
            Reader(path_, prefix_ + "dense_map.maps." + name + ".all.accuracy_m.").number(acc, "median");
      const auto share = [&](std::size_t i) {
        double v = 0;
        if (!is_plain_scalar(comp[i]) || !YAML::convert<double>::decode(comp[i], v) || !std::isfinite(v))
          all_in.fail(comp[i], "completeness_at[" + std::to_string(i) + "]", "expected a number");
        return v;
      };
      m.completeness_2cm = share(1);
      m.completeness_5cm = share(2);
      m.ghosting = all_in.number(all, "ghosting");
      out.push_back(m);
    }
    return out;
  }

  /// "place_recognition": counts always, labels when judged against ground truth.
  std::optional<PlaceMetrics> place(const YAML::Node& obj) const {
    const YAML::Node n = obj["place_recognition"];
    if (!n.IsDefined() || n.IsNull()) return std::nullopt;
    if (!n.IsMap()) fail(n, "place_recognition", "expected an object or null");
    const Reader in(path_, prefix_ + "place_recognition.");
    PlaceMetrics p;
    p.loops_proposed = in.integer(n, "loops_proposed");
    p.loops_accepted = in.integer(n, "loops_accepted");
    p.relocalisations = in.integer(n, "relocalisations");
    const auto opt = [&](const char* key, std::optional<int>* v) {
      if (n[key].IsDefined()) *v = in.integer(n, key);
    };
    opt("loops_true", &p.loops_true);
    opt("loops_false", &p.loops_false);
    opt("loops_missed", &p.loops_missed);
    opt("revisits", &p.revisits);
    opt("relocalisations_true", &p.relocalisations_true);
    opt("relocalisations_false", &p.relocalisations_false);
    return p;
  }

 private:
  std::string path_;
  std::string prefix_;
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
  const std::string text = read_file(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    throw IoError(path, "not valid JSON: nested too deeply for the parser", e.mark.line + 1);
  } catch (const YAML::Exception& e) {
    throw IoError(path, "not valid JSON: " + e.msg, e.mark.line + 1);
  }
  if (!root.IsMap()) throw IoError(path, "expected a JSON object at the top level");
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
               "expected 1 to " + std::to_string(eval::kMetricsVersion) + " (this pvbench reads up to version " +
                   std::to_string(eval::kMetricsVersion) + "), got " + std::to_string(v));
    m.version = v;
  }
  if (root["scenario"].IsDefined()) m.scenario = top.text(root, "scenario");
  const YAML::Node seed = root["seed"];
  if (seed.IsDefined() && !seed.IsNull()) {
    unsigned long long v = 0;
    if (!Reader::is_plain_scalar(seed) || seed.Scalar().empty() || seed.Scalar()[0] == '-' ||
        !YAML::convert<unsigned long long>::decode(seed, v))
      top.fail(seed, "seed", "expected a non-negative integer, got " + Reader::shown(seed));
    m.seed = v;
  }
  read_station(root["world"], &m);
  m.primary = top.run(root);
  const YAML::Node base = root["baseline"];
  if (base.IsDefined() && !base.IsNull()) {
    if (!base.IsMap()) top.fail(base, "baseline", "expected an object");
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
  YAML::Node root;
  try {
    root = YAML::Load(read_file(meta));
  } catch (const YAML::Exception& e) {
    throw IoError(meta, "not valid JSON: " + e.msg, e.mark.line + 1);
  }
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
