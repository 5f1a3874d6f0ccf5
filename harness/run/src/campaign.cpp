#include "pvb/run/campaign.hpp"

#include <sys/stat.h>
#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/run/run.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::run {
namespace {

struct Ctx {
  std::string file;
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& expected,
                         const std::string& got = {}) const {
    const int line = at.Mark().line;
    throw ConfigError(line >= 0 ? file + ":" + std::to_string(line + 1) : file, key, expected, got);
  }
};

/// Keys of a map, each once and known.
void check_keys(const Ctx& c, const YAML::Node& map, const std::string& path, const std::set<std::string>& known) {
  std::set<std::string> seen;
  std::string names;
  for (const std::string& k : known) names += (names.empty() ? "" : ", ") + k;
  for (const auto& kv : map) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "?";
    const std::string full = path.empty() ? key : path + "." + key;
    if (!known.count(key)) c.fail(kv.first, full, "a known key (" + names + ")", "unknown key");
    if (!seen.insert(key).second) c.fail(kv.first, full, "each key once", "a second " + key);
  }
}

std::string text(const Ctx& c, const YAML::Node& map, const std::string& key, const std::string& path,
                  bool required) {
  const YAML::Node& cmap = map;
  const YAML::Node n = cmap[key];
  if (!n.IsDefined() || n.IsNull()) {
    if (required) c.fail(map, path + "." + key, "a value (required)");
    return {};
  }
  if (!n.IsScalar() || n.Scalar().empty()) c.fail(n, path + "." + key, "a non-empty string");
  return n.Scalar();
}

CampaignSession read_session(const Ctx& c, const YAML::Node& n, const std::string& path, const std::string& dir) {
  if (!n.IsMap()) c.fail(n, path, "a session (a map of name, scenario, mode, map, start_m)");
  check_keys(c, n, path, {"name", "scenario", "mode", "map", "start_m"});
  CampaignSession s;
  s.name = text(c, n, "name", path, true);
  if (s.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") != std::string::npos)
    c.fail(n["name"], path + ".name", "letters, digits, '_' and '-' (it names a folder)", s.name);
  const auto& taken = campaign_top_level_names();
  if (std::find(taken.begin(), taken.end(), s.name) != taken.end()) {
    std::string list;
    for (const std::string& t : taken) list += (list.empty() ? "" : ", ") + t;
    c.fail(n["name"], path + ".name",
           "a name other than those the campaign writes beside the sessions' folders (" + list + ")", s.name);
  }
  const std::string scenario = text(c, n, "scenario", path, true);
  s.scenario_file = scenario[0] == '/' ? scenario : (std::filesystem::path(dir) / scenario).lexically_normal().string();
  struct stat st {};
  if (::stat(s.scenario_file.c_str(), &st) != 0)
    c.fail(n["scenario"], path + ".scenario", "an existing scenario file", s.scenario_file);
  const std::string mode = text(c, n, "mode", path, true);
  if (mode == "map") s.mode = SessionMode::kMap;
  else if (mode == "localise") s.mode = SessionMode::kLocalise;
  else if (mode == "extend") s.mode = SessionMode::kExtend;
  else c.fail(n["mode"], path + ".mode", "one of map, localise, extend", mode);
  s.map = text(c, n, "map", path, false);
  const YAML::Node& cn = n;
  const YAML::Node start = cn["start_m"];
  if (start.IsDefined() && !start.IsNull()) {
    double v = 0;
    if (!start.IsScalar() || !YAML::convert<double>::decode(start, v) || !std::isfinite(v) || v < 0)
      c.fail(start, path + ".start_m", "a distance along the route in metres, >= 0", start.IsScalar() ? start.Scalar() : "");
    s.start_m = v;
  }
  return s;
}

/// A session's map is an earlier one that leaves a map; a map session names none.
void check_maps(const Ctx& c, const YAML::Node& list, const Campaign& k) {
  for (std::size_t i = 0; i < k.sessions.size(); ++i) {
    const CampaignSession& s = k.sessions[i];
    const std::string path = "sessions[" + std::to_string(i) + "]";
    if (s.mode == SessionMode::kMap) {
      if (!s.map.empty()) c.fail(list[i]["map"], path + ".map", "no map for a map session (it makes one)", s.map);
      continue;
    }
    if (s.map.empty()) c.fail(list[i], path + ".map", "the earlier session whose map it starts from");
    const int j = k.index_of(s.map);
    if (j < 0 || j >= static_cast<int>(i))
      c.fail(list[i]["map"], path + ".map", "the name of an earlier session", s.map);
    if (k.sessions[static_cast<std::size_t>(j)].mode == SessionMode::kLocalise)
      c.fail(list[i]["map"], path + ".map", "a session that leaves a map (map or extend)", s.map + " (localise)");
  }
}

/// Every session's scenario, loaded before any session runs: its seed, and
/// its start_m against the route.
void check_scenarios(const Ctx& c, const YAML::Node& list, Campaign* k) {
  for (std::size_t i = 0; i < k->sessions.size(); ++i) {
    CampaignSession& s = k->sessions[i];
    const scenes::Scenario scenario = scenes::load_scenario(s.scenario_file);
    s.scenario_seed = scenario.seed;
    if (!s.start_m) continue;
    const std::string expected = start_m_expectation(scenario, *s.start_m, s.scenario_file);
    if (!expected.empty())
      c.fail(list[i]["start_m"], "sessions[" + std::to_string(i) + "].start_m", expected,
             format_g(*s.start_m));
  }
}

}  // namespace

const std::vector<std::string>& campaign_top_level_names() {
  static const std::vector<std::string> names = {"maps",       "campaign.json", "campaign.md", "matrix.svg",
                                                 "matrix.png", "index.html",    "stdout.log"};
  return names;
}

const char* to_string(SessionMode m) {
  switch (m) {
    case SessionMode::kMap:
      return "map";
    case SessionMode::kLocalise:
      return "localise";
    case SessionMode::kExtend:
      return "extend";
  }
  return "?";
}

int Campaign::index_of(const std::string& n) const {
  for (std::size_t i = 0; i < sessions.size(); ++i)
    if (sessions[i].name == n) return static_cast<int>(i);
  return -1;
}

Campaign load_campaign(const std::string& path) {
  const Ctx c{path};
  YAML::Node root;
  try {
    root = YAML::Load(read_file(path));
  } catch (const YAML::DeepRecursion& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1), "(syntax)", "YAML nested less deeply");
  } catch (const YAML::Exception& e) {
    throw ConfigError(path + ":" + std::to_string(e.mark.line + 1), "(syntax)", "valid YAML", e.msg);
  }
  if (!root.IsMap()) throw ConfigError(path, "(top level)", "a campaign: name, description, sessions");
  check_keys(c, root, "", {"name", "description", "sessions"});
  Campaign k;
  k.file = path;
  k.name = text(c, root, "name", "", true);
  k.description = text(c, root, "description", "", false);
  const YAML::Node& croot = root;
  const YAML::Node list = croot["sessions"];
  if (!list.IsDefined() || !list.IsSequence() || list.size() == 0)
    c.fail(list.IsDefined() ? list : root, "sessions", "a list of at least one session");
  const std::string dir = std::filesystem::path(path).parent_path().string();
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    k.sessions.push_back(read_session(c, list[i], "sessions[" + std::to_string(i) + "]", dir.empty() ? "." : dir));
    if (!names.insert(k.sessions.back().name).second)
      c.fail(list[i]["name"], "sessions[" + std::to_string(i) + "].name", "a name no other session has",
             k.sessions.back().name);
  }
  check_maps(c, list, k);
  check_scenarios(c, list, &k);
  return k;
}

}  // namespace pvb::run
