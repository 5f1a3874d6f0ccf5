#pragma once
// The options of the commands that can start from a saved map or save one
// (run, slam, camera): --map, --map-mode, --save-map (docs/map_reuse.md).
#include <CLI/CLI.hpp>
#include <string>

#include "count_option.hpp"
#include "pvb/run/map_session.hpp"

namespace pvb::cli {

/// Adds --map, --map-mode (kept as text in *mode for run::parse_map_use)
/// and --save-map to `sub`.
inline void add_map_options(CLI::App* sub, run::MapOptions* map, std::string* mode) {
  const std::string command = sub->get_name();
  sub->add_option("--map", map->load_path, "start from this saved map (with --map-mode)")
      ->check(path_check(command, "--map"));
  sub->add_option("--map-mode", *mode,
                  "localise: track in the saved map without changing it; extend: add to it");
  sub->add_option("--save-map", map->save_path, "save the final map here (a new map, or the extended one)")
      ->check(path_check(command, "--save-map"));
}

}  // namespace pvb::cli
