#include "pvb/openni/sim_uri.hpp"

#include <cstdlib>

#include "pvb/common/error.hpp"

namespace pvb::openni {
namespace {

long long parse_int(const std::string& uri, const std::string& key, const std::string& value,
                    long long min_value) {
  char* end = nullptr;
  const long long v = std::strtoll(value.c_str(), &end, 10);
  if (value.empty() || *end != '\0' || v < min_value)
    throw ConfigError(uri, key, "an integer >= " + std::to_string(min_value), "'" + value + "'");
  return v;
}

}  // namespace

bool is_sim_uri(const std::string& uri) { return uri.rfind(kSimScheme, 0) == 0; }

SimUri parse_sim_uri(const std::string& uri) {
  if (!is_sim_uri(uri)) throw ConfigError(uri, "uri", "sim://<scenario file>", "'" + uri + "'");
  SimUri out;
  const std::string rest = uri.substr(std::string(kSimScheme).size());
  const std::size_t q = rest.find('?');
  out.scenario_path = rest.substr(0, q);
  if (out.scenario_path.empty()) throw ConfigError(uri, "uri", "sim://<scenario file>", "no scenario file");
  if (q == std::string::npos) return out;
  std::string query = rest.substr(q + 1);
  std::size_t pos = 0;
  while (pos <= query.size()) {
    const std::size_t amp = query.find('&', pos);
    const std::string item = query.substr(pos, amp == std::string::npos ? std::string::npos : amp - pos);
    pos = amp == std::string::npos ? query.size() + 1 : amp + 1;
    if (item.empty()) continue;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) throw ConfigError(uri, item, "key=value", "'" + item + "'");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "seed") {
      out.seed = static_cast<std::uint64_t>(parse_int(uri, key, value, 0));
    } else if (key == "frames") {
      out.frames = static_cast<int>(parse_int(uri, key, value, 1));
    } else if (key == "unplug_after") {
      out.unplug_after = static_cast<int>(parse_int(uri, key, value, 1));
    } else if (key == "stall_after") {
      out.stall_after = static_cast<int>(parse_int(uri, key, value, 1));
    } else if (key == "gl") {
      if (value != "auto" && value != "egl" && value != "osmesa")
        throw ConfigError(uri, key, "auto, egl or osmesa", "'" + value + "'");
      out.gl = value;
    } else {
      throw ConfigError(uri, key, "one of seed, frames, gl, unplug_after, stall_after", "'" + key + "'");
    }
  }
  return out;
}

}  // namespace pvb::openni
