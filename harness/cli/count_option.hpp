#pragma once
// A count on the command line (`--frames N`), read as text and checked here
// rather than by CLI11: CLI11 turns "-3" into a huge unsigned number, and its
// range check prints the largest double (309 digits) and exits 105.  A bad
// count is one `pvbench: error:` line and exit 1, like any other bad input.
#include <cstddef>
#include <string>

#include "pvb/common/error.hpp"

namespace pvb::cli {

/// The whole number in `text`, in [min_value, max_value]; otherwise throws
/// ConfigError("pvbench COMMAND", OPTION, "a whole number in [min, max]" + note, text).
inline std::size_t parse_count(const std::string& command, const std::string& option, const std::string& text,
                               std::size_t min_value, std::size_t max_value, const std::string& note = {}) {
  std::size_t value = 0;
  bool ok = !text.empty() && text.size() <= 18;
  for (char c : text) {
    ok = ok && c >= '0' && c <= '9';
    if (ok) value = value * 10 + static_cast<std::size_t>(c - '0');
  }
  if (!ok || value < min_value || value > max_value)
    throw ConfigError(
        "pvbench " + command, option,
        "a whole number in [" + std::to_string(min_value) + ", " + std::to_string(max_value) + "]" + note,
        text);
  return value;
}

}  // namespace pvb::cli
