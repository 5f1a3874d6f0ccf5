#include "pvb/campaign/campaign.hpp"

#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/common/yaml_reader.hpp"
#include "pvb/run/run.hpp"
#include "pvb/scenes/scenario.hpp"

namespace pvb::run {
namespace {

using Ctx = yaml::ReadContext;

CampaignSession read_session(const Ctx& c, const YAML::Node& n, const std::string& path, const std::string& dir) {
  if (!n.IsMap()) c.fail(path, n, "a session (a map of name, scenario, mode, map, start_m)");
  yaml::MapReader r(n, c, path);
  r.keys({"name", "scenario", "mode", "map", "start_m"});
  CampaignSession s;
  s.name = r.text("name", true);
  if (s.name.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") != std::string::npos)
    r.fail(r.full("name"), n["name"], "letters, digits, '_' and '-' (it names a folder)", s.name);
  const auto& taken = campaign_top_level_names();
  if (std::find(taken.begin(), taken.end(), s.name) != taken.end()) {
    std::string list;
    for (const std::string& t : taken) list += (list.empty() ? "" : ", ") + t;
    r.fail(r.full("name"), n["name"],
           "a name other than those the campaign writes beside the sessions' folders (" + list + ")", s.name);
  }
  const std::string scenario = r.text("scenario", true);
  s.scenario_file = scenario[0] == '/' ? scenario : (std::filesystem::path(dir) / scenario).lexically_normal().string();
  struct stat st {};
  if (::stat(s.scenario_file.c_str(), &st) != 0)
    r.fail(r.full("scenario"), n["scenario"], "an existing scenario file", s.scenario_file);
  const std::string mode = r.text("mode", true);
  if (mode == "map") s.mode = SessionMode::kMap;
  else if (mode == "localise") s.mode = SessionMode::kLocalise;
  else if (mode == "extend") s.mode = SessionMode::kExtend;
  else r.fail(r.full("mode"), n["mode"], "one of map, localise, extend", mode);
  s.map = r.text("map", false);
  const YAML::Node start = r.child("start_m");
  if (start) {
    double v = 0;
    if (!yaml::decode_number(start, c, &v) || v < 0)
      r.fail(r.full("start_m"), start, "a distance along the route in metres, >= 0", start.IsScalar() ? start.Scalar() : "");
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
      if (!s.map.empty()) c.fail(path + ".map", list[i]["map"], "no map for a map session (it makes one)", s.map);
      continue;
    }
    if (s.map.empty()) c.fail(path + ".map", list[i], "the earlier session whose map it starts from");
    const int j = k.index_of(s.map);
    if (j < 0 || j >= static_cast<int>(i))
      c.fail(path + ".map", list[i]["map"], "the name of an earlier session", s.map);
    if (k.sessions[static_cast<std::size_t>(j)].mode == SessionMode::kLocalise)
      c.fail(path + ".map", list[i]["map"], "a session that leaves a map (map or extend)", s.map + " (localise)");
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
      c.fail("sessions[" + std::to_string(i) + "].start_m", list[i]["start_m"], expected,
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
  const YAML::Node root = yaml::parse(read_file(path), c);
  if (!root.IsMap()) throw ConfigError(path, "(top level)", "a campaign: name, description, sessions");
  yaml::MapReader top(root, c, "");
  top.keys({"name", "description", "sessions"});
  Campaign k;
  k.file = path;
  k.name = top.text("name", true);
  k.description = top.text("description", false);
  const YAML::Node list = root["sessions"];
  if (!list.IsDefined() || !list.IsSequence() || list.size() == 0)
    c.fail("sessions", list.IsDefined() ? list : root, "a list of at least one session");
  const std::string dir = std::filesystem::path(path).parent_path().string();
  std::set<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    k.sessions.push_back(read_session(c, list[i], "sessions[" + std::to_string(i) + "]", dir.empty() ? "." : dir));
    if (!names.insert(k.sessions.back().name).second)
      c.fail("sessions[" + std::to_string(i) + "].name", list[i]["name"], "a name no other session has",
             k.sessions.back().name);
  }
  check_maps(c, list, k);
  check_scenarios(c, list, &k);
  return k;
}

}  // namespace pvb::run
