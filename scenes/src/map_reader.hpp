#pragma once
// The strict reader of a scenario's maps: pvb::yaml::MapReader (every key
// read is recorded, finish() rejects any key that was not), whose errors
// name the file and line where the key was written (a derived file or one
// of its bases, scenario_document.hpp) and the full key; plus the vectors
// a scenario gives.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>

#include "pvb/common/yaml_reader.hpp"
#include "scenario_document.hpp"

namespace pvb::scenes::detail {

using yaml::kInf;

/// What every reader of one scenario shares: the file given and where each
/// key of the (merged) document was written, which also locates the keys
/// in errors.
struct ReadContext : yaml::ReadContext {
  ReadContext(std::string file_given, const KeyOrigins* key_origins)
      : yaml::ReadContext{std::move(file_given), key_origins}, origins(key_origins) {}
  const KeyOrigins* origins = nullptr;
};

class MapReader : public yaml::MapReader {
 public:
  using yaml::MapReader::MapReader;

  Eigen::Vector2d vec2(const std::string& key, const Eigen::Vector2d& def, double lo, double hi) {
    const auto v = numbers(key, 2, lo, hi);
    return v.empty() ? def : Eigen::Vector2d(v[0], v[1]);
  }

  /// A (min, max) pair with min <= max.
  Eigen::Vector2d range(const std::string& key, const Eigen::Vector2d& def, double lo, double hi) {
    const YAML::Node n = node()[key];
    const Eigen::Vector2d v = vec2(key, def, lo, hi);
    if (v.x() > v.y()) fail(full(key), n, "[min, max] with min <= max");
    return v;
  }
};

/// Runs `fn` on the map under `key` of `parent` if present, then finish().
inline void with_map(MapReader& parent, const std::string& key, const std::function<void(MapReader&)>& fn) {
  const YAML::Node n = parent.child(key);
  if (!n) return;
  MapReader r(n, parent.context(), parent.full(key));
  fn(r);
  r.finish();
}

}  // namespace pvb::scenes::detail
