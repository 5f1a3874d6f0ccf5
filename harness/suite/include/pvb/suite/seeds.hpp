#pragma once
// Seed lists for sweeps: "1-20", "1,3,5", "1-5,9".
#include <cstdint>
#include <string>
#include <vector>

namespace pvb::suite {

/// Parses a seed list: comma-separated items, each a non-negative integer or
/// an inclusive range "a-b" with a <= b.  Seeds keep the order given; a seed
/// given twice, an empty item, a reversed range or more than `max_seeds`
/// seeds is a ConfigError naming `what` (e.g. "--seeds").
std::vector<std::uint64_t> parse_seed_list(const std::string& text, const std::string& what = "--seeds",
                                           std::size_t max_seeds = 100000);

}  // namespace pvb::suite
