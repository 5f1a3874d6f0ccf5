#pragma once
// A count on the command line (`--frames N`), read as text and checked here
// rather than by CLI11: CLI11 turns "-3" into a huge unsigned number, and its
// range check prints the largest double (309 digits) and exits 105.  A bad
// count is one `pvbench: error:` line and exit 1, like any other bad input.
#include <CLI/CLI.hpp>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>

#include "pvb/common/error.hpp"

namespace pvb::cli {

/// The whole number in `text` if it is one in [0, max_value].
inline bool parse_whole(const std::string& text, std::uint64_t max_value, std::uint64_t* value) {
  if (text.empty() || text.size() > 20) return false;
  std::uint64_t v = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return false;
    const auto digit = static_cast<std::uint64_t>(c - '0');
    if (v > (max_value - digit) / 10) return false;
    v = v * 10 + digit;
  }
  *value = v;
  return true;
}

/// The whole number in `text`, in [min_value, max_value]; otherwise throws
/// ConfigError("pvbench COMMAND", OPTION, "a whole number in [min, max]" + note, text).
inline std::size_t parse_count(const std::string& command, const std::string& option, const std::string& text,
                               std::size_t min_value, std::size_t max_value, const std::string& note = {}) {
  std::uint64_t value = 0;
  if (!parse_whole(text, max_value, &value) || value < min_value)
    throw ConfigError(
        "pvbench " + command, option,
        "a whole number in [" + std::to_string(min_value) + ", " + std::to_string(max_value) + "]" + note,
        text);
  return static_cast<std::size_t>(value);
}

/// A CLI11 check for a seed option (`--seed S`): a whole number in
/// [0, max_value].  CLI11 itself wraps "-1" to the largest unsigned value;
/// here anything else throws ConfigError from the parse, which main reports
/// as one `pvbench: error:` line with exit 1.
inline CLI::Validator seed_check(const std::string& command, const std::string& option,
                                 std::uint64_t max_value = std::numeric_limits<std::uint32_t>::max()) {
  return CLI::Validator(
      [=](std::string& text) {
        std::uint64_t value = 0;
        if (!parse_whole(text, max_value, &value))
          throw ConfigError("pvbench " + command, option,
                            "a whole number in [0, " + std::to_string(max_value) + "]", text);
        return std::string();
      },
      "SEED");
}

/// A CLI11 check for a path option: an empty path (`--save-map ''`) names
/// no file, and would otherwise read as the option not given at all.
inline CLI::Validator path_check(const std::string& command, const std::string& option) {
  return CLI::Validator(
      [=](std::string& text) {
        if (text.empty()) throw ConfigError("pvbench " + command, option, "a path", "an empty one");
        return std::string();
      },
      "PATH");
}

}  // namespace pvb::cli
