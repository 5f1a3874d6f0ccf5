#include "scenario_document.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <regex>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::scenes::detail {
namespace {

namespace fs = std::filesystem;

/// Bases of bases: a chain longer than this is a mistake, not a station.
constexpr int kMaxBaseDepth = 16;

/// The keys a derived file may give: what changes from day to day.  "X.*"
/// allows every key below X; "[*]" stands for any list index.
const std::vector<std::string>& day_keys() {
  static const std::vector<std::string> keys = {
      "base", "name", "description", "seed", "station_seed", "duration_s", "site", "site.*", "light", "light.*",
      "ground", "ground.friction", "ground.softness", "vegetation", "vegetation.growth", "pv_arrays", "pv_arrays[*]", "pv_arrays[*].dirt", "pv_arrays[*].glass", "pv_arrays[*].tracker",
      "pv_arrays[*].tracker.rotation_deg", "plant", "plant.dirt", "plant.glass", "plant.tracker", "plant.tracker.rotation_deg", "camera", "camera.model", "camera.stereo", "camera.stereo.*", "camera.depth_noise", "camera.depth_noise.*", "camera.rgb",
      "camera.rgb.*", "route", "route.on_loss", "route.start_m", "kidnap", "kidnap.*", "cover", "cover.*",
      "expect", "expect.*", "slam", "slam.*"};
  return keys;
}

bool is_day_key(const std::string& full) {
  static const std::regex index(R"(\[[0-9]+\])");
  const std::string pattern = std::regex_replace(full, index, "[*]");
  for (const std::string& k : day_keys()) {
    if (k == pattern) return true;
    if (k.size() > 2 && k.compare(k.size() - 2, 2, ".*") == 0 &&
        pattern.compare(0, k.size() - 1, k, 0, k.size() - 1) == 0)
      return true;
  }
  return false;
}

std::string at(const KeyOrigin& o) { return o.line > 0 ? o.file + ":" + std::to_string(o.line) : o.file; }

/// The size limit as errors give it, in bytes too: a file just over it
/// is never said to be the limit's size.
std::string scenario_size_limit() {
  return "a scenario file of at most " + std::to_string(kMaxScenarioBytes / 1024) + " KiB (" +
         std::to_string(kMaxScenarioBytes) + " bytes)";
}

YAML::Node parse_yaml(const std::string& text, const std::string& origin) {
  // The parser takes about 100 bytes of memory per byte of text: a file far
  // larger than any scene the renderer draws is refused before it is parsed.
  if (text.size() > kMaxScenarioBytes)
    throw ConfigError(origin, "(file)",
                      scenario_size_limit() + " (the largest scene the renderer draws takes far less)",
                      std::to_string(text.size()) + " bytes");
  // YAML is text: yaml-cpp reads a raw NUL byte as the start of an escape
  // and names some other character, so a NUL (a binary file, a damaged
  // one) is named here, with its line.
  if (const std::size_t nul = text.find('\0'); nul != std::string::npos) {
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(nul), '\n');
    throw ConfigError(origin + ":" + std::to_string(line), "(file)", "YAML text (a NUL byte is never in one)",
                      "a NUL byte at byte " + std::to_string(nul));
  }
  // Syntax errors, and a key given twice in one map (yaml-cpp keeps both
  // and finds the first, so the second value would go unread and unchecked).
  const YAML::Node root = yaml::parse(text, yaml::ReadContext{origin});
  if (!root.IsDefined() || root.IsNull())
    throw ConfigError(origin, "(top level)", "a scenario mapping", "an empty file");
  if (!root.IsMap()) throw ConfigError(origin + ":1", "(top level)", "a mapping of keys");
  return root;
}

/// Records where every key of `n` was written (each key once in its map:
/// parse_yaml checked).
void collect_origins(const YAML::Node& n, const std::string& file, int depth, const std::string& path,
                     KeyOrigins* origins) {
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) {
      const std::string item = path + "[" + std::to_string(i) + "]";
      origins->set(item, {file, n[i].Mark().line + 1, depth});
      collect_origins(n[i], file, depth, item, origins);
    }
    return;
  }
  if (!n.IsMap()) return;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar()) continue;  // the reader names a non-scalar key
    const std::string full = path.empty() ? kv.first.Scalar() : path + "." + kv.first.Scalar();
    origins->set(full, {file, kv.first.Mark().line + 1, depth});
    collect_origins(kv.second, file, depth, full, origins);
  }
}

/// A derived file changes the day, never the station: the keys of `n` it
/// may not give, with where each was written.  Not refused here: an unknown
/// key is named as one by the reader first.
void find_station_keys(const YAML::Node& n, const std::string& path, const KeyOrigins& origins,
                       std::vector<StationKey>* out) {
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) {
      const std::string item = path + "[" + std::to_string(i) + "]";
      if (!is_day_key(item)) out->push_back({item, origins.where(item, "")});
      find_station_keys(n[i], item, origins, out);
    }
    return;
  }
  if (!n.IsMap()) return;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar()) continue;
    const std::string full = path.empty() ? kv.first.Scalar() : path + "." + kv.first.Scalar();
    if (!is_day_key(full)) out->push_back({full, origins.where(full, "")});
    find_station_keys(kv.second, full, origins, out);
  }
}

/// Puts `over` (a derived file's map at `path`) into `into` (its base's).
/// Maps merge key by key; pv_arrays merge item by item (a day file changes
/// the arrays the station has); anything else is replaced.
void merge_map(YAML::Node into, const YAML::Node& over, const std::string& path, const KeyOrigins& over_origins,
               KeyOrigins* origins) {
  for (const auto& kv : over) {
    const std::string key = kv.first.Scalar();
    const std::string full = path.empty() ? key : path + "." + key;
    YAML::Node target = into[key];
    if (target.IsMap() && kv.second.IsMap()) {
      origins->set(full, *over_origins.find(full));
      merge_map(target, kv.second, full, over_origins, origins);
    } else if (full == "pv_arrays" && target.IsSequence() && kv.second.IsSequence()) {
      if (kv.second.size() > target.size())
        throw ConfigError(over_origins.where(full + "[" + std::to_string(target.size()) + "]", ""), full,
                          "at most the station's " + std::to_string(target.size()) +
                              " arrays (a derived file changes the arrays there are)",
                          std::to_string(kv.second.size()) + " arrays");
      for (std::size_t i = 0; i < kv.second.size(); ++i) {
        const std::string item = full + "[" + std::to_string(i) + "]";
        if (!kv.second[i].IsMap() || !target[i].IsMap()) continue;  // the reader says what is wrong
        merge_map(target[i], kv.second[i], item, over_origins, origins);
      }
    } else {
      origins->erase_below(full);
      into[key] = YAML::Clone(kv.second);
      origins->copy_below(over_origins, full);
    }
  }
}

/// The station seed a base fixes: its station_seed, else its seed, else 0.
/// The base's station seed and where it was written (a copy: the base's
/// origins change when the derived file is merged over them).
std::pair<std::string, std::optional<KeyOrigin>> station_seed_of(const ScenarioDocument& base) {
  for (const char* key : {"station_seed", "seed"}) {
    const YAML::Node& root = base.root;
    const YAML::Node v = root[key];
    if (!v.IsDefined() || !v.IsScalar()) continue;
    const KeyOrigin* origin = base.origins.find(key);
    return {v.Scalar(), origin ? std::optional<KeyOrigin>(*origin) : std::nullopt};
  }
  return {"0", std::nullopt};
}

ScenarioDocument read_document(const std::string& text, const std::string& origin, int depth,
                               std::vector<std::string>* chain);

/// The base that `doc` names, merged under it.
void apply_base(ScenarioDocument& doc, const YAML::Node& base_key, int depth, std::vector<std::string>* chain) {
  const std::string where = doc.origins.where("base", doc.file);
  if (!base_key.IsScalar() || base_key.Scalar().empty())
    throw ConfigError(where, "base", "the scenario file this one derives from");
  const fs::path base_path = fs::path(doc.file).parent_path() / base_key.Scalar();
  const std::string base_file = base_path.lexically_normal().string();
  struct stat st {};
  if (::stat(base_file.c_str(), &st) != 0)
    throw ConfigError(where, "base", "an existing scenario file", base_file + " (no such file)");
  const std::string canonical = fs::weakly_canonical(base_path).string();
  for (const std::string& c : *chain)
    if (c == canonical) throw ConfigError(where, "base", "a file that does not derive from itself", base_file);
  if (depth + 1 > kMaxBaseDepth)
    throw ConfigError(where, "base", "at most " + std::to_string(kMaxBaseDepth) + " bases in a chain");
  require_regular_file(base_file);
  chain->push_back(canonical);
  ScenarioDocument base = read_document(read_file(base_file), base_file, depth + 1, chain);
  chain->pop_back();
  std::vector<StationKey> station_keys = base.station_keys;  // a derived base's own, first
  find_station_keys(doc.root, "", doc.origins, &station_keys);
  // A derived file keeps its base's station: the station seed is pinned.
  const auto [station_seed, seed_origin] = station_seed_of(base);
  const YAML::Node& droot = doc.root;
  const YAML::Node pinned = droot["station_seed"];
  if (pinned.IsDefined() && (!pinned.IsScalar() || pinned.Scalar() != station_seed))
    throw ConfigError(doc.origins.where("station_seed", doc.file), "station_seed",
                      "the station seed of its base, " + station_seed + " (" + base_file +
                          "): a derived file keeps its station",
                      pinned.IsScalar() ? pinned.Scalar() : "a non-scalar");
  YAML::Node derived = YAML::Clone(doc.root);
  derived.remove("base");
  merge_map(base.root, derived, "", doc.origins, &base.origins);
  if (!pinned.IsDefined()) {
    base.root["station_seed"] = station_seed;
    base.origins.set("station_seed", seed_origin ? *seed_origin : KeyOrigin{base_file, 0, depth + 1});
  }
  base.origins.erase_below("base");
  base.bases.insert(base.bases.begin(), base_file);
  doc.root = base.root;
  doc.origins = base.origins;
  doc.bases = base.bases;
  doc.station_keys = std::move(station_keys);
}

ScenarioDocument read_document(const std::string& text, const std::string& origin, int depth,
                               std::vector<std::string>* chain) {
  ScenarioDocument doc;
  doc.file = origin;
  doc.root = parse_yaml(text, origin);
  collect_origins(doc.root, origin, depth, "", &doc.origins);
  const YAML::Node& root = doc.root;
  const YAML::Node base_key = root["base"];
  if (base_key.IsDefined()) apply_base(doc, base_key, depth, chain);
  return doc;
}

}  // namespace

void refuse_station_keys(const ScenarioDocument& doc) {
  if (doc.station_keys.empty()) return;
  std::string allowed;
  for (const std::string& k : day_keys())
    if (k.find('*') == std::string::npos || k.size() < 3 || k.compare(k.size() - 2, 2, ".*") != 0)
      allowed += (allowed.empty() ? "" : ", ") + k;
  const StationKey& first = doc.station_keys.front();
  throw ConfigError(first.where, first.key,
                    "a key a derived file may change (" + allowed +
                        "; and whatever is below site, light, "
                        "camera.stereo, camera.depth_noise, camera.rgb, kidnap, cover, expect and slam)",
                    "a key of the station, which stays as its base has it");
}

const KeyOrigin* KeyOrigins::find(const std::string& key) const {
  const auto it = map_.find(key);
  return it == map_.end() ? nullptr : &it->second;
}

void KeyOrigins::erase_below(const std::string& key) {
  for (auto it = map_.lower_bound(key); it != map_.end() && it->first.compare(0, key.size(), key) == 0;) {
    const char next = it->first.size() > key.size() ? it->first[key.size()] : '\0';
    if (next == '\0' || next == '.' || next == '[')
      it = map_.erase(it);
    else
      ++it;
  }
}

void KeyOrigins::copy_below(const KeyOrigins& from, const std::string& key) {
  for (auto it = from.map_.lower_bound(key); it != from.map_.end() && it->first.compare(0, key.size(), key) == 0;
       ++it) {
    const char next = it->first.size() > key.size() ? it->first[key.size()] : '\0';
    if (next == '\0' || next == '.' || next == '[') map_[it->first] = it->second;
  }
}

std::string KeyOrigins::where(const std::string& key, const std::string& fallback) const {
  std::string k = key;
  while (!k.empty()) {
    if (const KeyOrigin* o = find(k)) return at(*o);
    const std::size_t cut = k.find_last_of(".[");
    if (cut == std::string::npos) break;
    k.erase(cut);
  }
  return fallback;
}

ScenarioDocument load_document(const std::string& path) {
  require_regular_file(path);
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && static_cast<std::size_t>(st.st_size) > kMaxScenarioBytes)
    throw ConfigError(path, "(file)", scenario_size_limit(), std::to_string(st.st_size) + " bytes");
  return parse_document(read_file(path), path);
}

ScenarioDocument parse_document(const std::string& text, const std::string& origin) {
  std::error_code ec;
  std::vector<std::string> chain = {fs::weakly_canonical(fs::path(origin), ec).string()};
  return read_document(text, origin, 0, &chain);
}

}  // namespace pvb::scenes::detail
