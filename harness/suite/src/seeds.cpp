#include "pvb/suite/seeds.hpp"

#include <limits>
#include <set>

#include "pvb/common/error.hpp"

namespace pvb::suite {
namespace {

constexpr const char* kSyntax = "a seed list like 1-20, 1,3,5 or 1-5,9";

// A non-negative decimal integer filling the whole of `s`.
bool parse_u64(const std::string& s, std::uint64_t* out) {
  if (s.empty()) return false;
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    const auto d = static_cast<std::uint64_t>(c - '0');
    if (v > (kMax - d) / 10) return false;  // overflow
    v = v * 10 + d;
  }
  *out = v;
  return true;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

}  // namespace

std::vector<std::uint64_t> parse_seed_list(const std::string& text, const std::string& what,
                                           std::size_t max_seeds) {
  if (trim(text).empty()) throw ConfigError("command line", what, kSyntax, "an empty list");
  std::vector<std::uint64_t> seeds;
  std::set<std::uint64_t> seen;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = text.find(',', pos);
    const std::string item =
        trim(text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
    if (item.empty())
      throw ConfigError("command line", what, kSyntax + std::string(" (an empty item)"), text);
    std::uint64_t lo = 0, hi = 0;
    const std::size_t dash = item.find('-');
    if (dash == std::string::npos) {
      if (!parse_u64(item, &lo)) throw ConfigError("command line", what, kSyntax, "'" + item + "'");
      hi = lo;
    } else {
      if (!parse_u64(trim(item.substr(0, dash)), &lo) || !parse_u64(trim(item.substr(dash + 1)), &hi))
        throw ConfigError("command line", what, kSyntax, "'" + item + "'");
      if (lo > hi) throw ConfigError("command line", what, "a range a-b with a <= b", "'" + item + "'");
    }
    if (hi - lo >= max_seeds || seeds.size() + (hi - lo + 1) > max_seeds)
      throw ConfigError("command line", what, "at most " + std::to_string(max_seeds) + " seeds", text);
    for (std::uint64_t s = lo;; ++s) {
      if (!seen.insert(s).second)
        throw ConfigError("command line", what, "each seed once", "seed " + std::to_string(s) + " twice");
      seeds.push_back(s);
      if (s == hi) break;
    }
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return seeds;
}

}  // namespace pvb::suite
