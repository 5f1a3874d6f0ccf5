#pragma once
// The URI of the simulator's virtual OpenNI2 device:
//
//   sim://<scenario file>[?key=value&...]
//
// keys: seed (overrides the scenario seed), frames (stream length; default
// the scenario's duration), gl (auto|egl|osmesa), unplug_after (the device
// reports itself unplugged after serving this many frames: a test hook for
// the harness's disconnect path), stall_after (the device stops serving
// after this many frames but stays connected: a hung camera, for the
// harness's timeout and Ctrl-C paths).  Shared by the driver plug-in and the
// harness, so both read a URI the same way.
#include <cstdint>
#include <optional>
#include <string>

namespace pvb::openni {

struct SimUri {
  std::string scenario_path;  ///< as written in the URI
  std::optional<std::uint64_t> seed;
  int frames = 0;  ///< 0: the scenario's duration
  std::string gl = "auto";
  int unplug_after = 0;  ///< 0: never
  int stall_after = 0;   ///< 0: never
};

inline constexpr const char* kSimScheme = "sim://";

/// True when `uri` names the simulator device.
bool is_sim_uri(const std::string& uri);

/// Parses a sim:// URI.  Throws ConfigError(uri, key, expected, got) for an
/// unknown key or a malformed value, and for a URI without a scenario path.
SimUri parse_sim_uri(const std::string& uri);

}  // namespace pvb::openni
