#pragma once
// --sensors SETUP, shared by slam, run, camera and sweep: overrides the
// settings' System.Sensors (docs/slam.md, "Sensor setups").  The text is
// checked when the command runs (run::parse_sensors_option: one error line
// naming the flag and the accepted values).
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "pvb/common/error.hpp"
#include "pvb/run/sensor_setup.hpp"

namespace pvb::cli {

inline void add_sensors_option(CLI::App* sub, std::string* text) {
  sub->add_option("--sensors", *text,
                  std::string("sensors the SLAM system fuses: ") + sensor::sensor_setup_values() +
                      " (default: the settings' System.Sensors, else camera)")
      ->check(CLI::Validator(
          [](std::string& value) {  // an empty value is a mistake, not "the default"
            if (value.empty()) throw ConfigError("command line", "--sensors", sensor::sensor_setup_values(), "''");
            return std::string();
          },
          "SETUP"));
}

/// The setup --sensors names; nullopt when the flag was not given.
inline std::optional<sensor::SensorSetup> sensors_from_flag(const std::string& text) {
  if (text.empty()) return std::nullopt;
  return run::parse_sensors_option(text, "--sensors");
}

}  // namespace pvb::cli
