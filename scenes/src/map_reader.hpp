#pragma once
// The strict reader of one YAML map of a scenario: every key read is
// recorded, finish() rejects any key that was not, and errors name the file
// and line where the key was written (a derived file or one of its bases,
// scenario_document.hpp) and the full key.
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "scenario_document.hpp"

namespace pvb::scenes::detail {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// What every reader of one document shares: the file given and where each
/// key of the (merged) document was written.
struct ReadContext {
  std::string file;
  const KeyOrigins* origins = nullptr;
};

// Strict reader over one YAML map: every key read is recorded, and finish()
// rejects any key that was not read.  Errors name file:line and the full key.
class MapReader {
 public:
  MapReader(const YAML::Node& node, const ReadContext& ctx, std::string path)
      : node_(node), ctx_(ctx), path_(std::move(path)) {
    if (!node_.IsMap()) fail(path_.empty() ? "(top level)" : path_, node_, "a mapping of keys");
  }

  bool has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }

  double number(const std::string& key, double def, double lo, double hi) {
    const YAML::Node n = take(key);
    if (!n) return def;
    double v = 0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
      fail(full(key), n, "a number", scalar_text(n));
    check_range(key, n, v, lo, hi);
    return v;
  }

  int integer(const std::string& key, int def, int lo, int hi) {
    const YAML::Node n = take(key);
    if (!n) return def;
    long long v = 0;
    if (!n.IsScalar() || !YAML::convert<long long>::decode(n, v))
      fail(full(key), n, "an integer", scalar_text(n));
    check_range(key, n, static_cast<double>(v), lo, hi);
    return static_cast<int>(v);
  }

  std::uint64_t seed(const std::string& key, std::uint64_t def) {
    const YAML::Node n = take(key);
    if (!n) return def;
    unsigned long long v = 0;
    if (!n.IsScalar() || n.Scalar().empty() || n.Scalar()[0] == '-' ||
        !YAML::convert<unsigned long long>::decode(n, v))
      fail(full(key), n, "a non-negative integer", scalar_text(n));
    return v;
  }

  bool boolean(const std::string& key, bool def) {
    const YAML::Node n = take(key);
    if (!n) return def;
    bool v = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v))
      fail(full(key), n, "true or false", scalar_text(n));
    return v;
  }

  /// A string of text: no control characters (a quoted "\0" or "\x07" is
  /// one; a NUL would cut the scene's XML short) but tabs and line breaks.
  std::string string(const std::string& key, const std::string& def) {
    const YAML::Node n = take(key);
    if (!n) return def;
    if (!n.IsScalar()) fail(full(key), n, "a string");
    for (const char c : n.Scalar())
      if ((static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f)
        fail(full(key), n, "a string without control characters", printable(n.Scalar()));
    return n.Scalar();
  }

  template <typename Enum>
  Enum choice(const std::string& key, Enum def, const std::vector<std::pair<std::string, Enum>>& options) {
    const YAML::Node n = take(key);
    if (!n) return def;
    std::string names;
    for (const auto& o : options) names += (names.empty() ? "" : ", ") + o.first;
    if (!n.IsScalar()) fail(full(key), n, "one of " + names);
    for (const auto& o : options)
      if (o.first == n.Scalar()) return o.second;
    fail(full(key), n, "one of " + names, n.Scalar());
  }

  /// A list of `size` numbers each in [lo, hi].
  std::vector<double> numbers(const std::string& key, std::size_t size, double lo, double hi) {
    const YAML::Node n = take(key);
    if (!n) return {};
    const std::string what = "a list of " + std::to_string(size) + " numbers";
    if (!n.IsSequence() || n.size() != size) fail(full(key), n, what);
    std::vector<double> out;
    for (std::size_t i = 0; i < size; ++i) {
      double v = 0;
      if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v) || !std::isfinite(v))
        fail(full(key) + "[" + std::to_string(i) + "]", n[i], "a number", scalar_text(n[i]));
      check_range(key + "[" + std::to_string(i) + "]", n[i], v, lo, hi);
      out.push_back(v);
    }
    return out;
  }

  Eigen::Vector2d vec2(const std::string& key, const Eigen::Vector2d& def, double lo, double hi) {
    const auto v = numbers(key, 2, lo, hi);
    return v.empty() ? def : Eigen::Vector2d(v[0], v[1]);
  }

  /// A (min, max) pair with min <= max.
  Eigen::Vector2d range(const std::string& key, const Eigen::Vector2d& def, double lo, double hi) {
    const YAML::Node n = node_[key];
    const Eigen::Vector2d v = vec2(key, def, lo, hi);
    if (v.x() > v.y()) fail(full(key), n, "[min, max] with min <= max");
    return v;
  }

  /// Sub-map reader (empty node -> absent).
  YAML::Node child(const std::string& key) { return take(key); }
  std::string full(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
  const ReadContext& context() const { return ctx_; }

  /// Rejects keys that were never read.
  void finish() const {
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) fail(full("?"), kv.first, "a key name", "a list or a map as a key");
      const std::string key = kv.first.as<std::string>();
      if (read_.count(key) == 0) {
        std::string known;
        for (const auto& k : read_) known += (known.empty() ? "" : ", ") + k;
        fail(full(key), kv.first, "a known key (" + known + ")", "unknown key");
      }
    }
  }

  /// Throws ConfigError for `key` (its full name), naming the file and line
  /// it was written on: the key's own, else the node's in the file given.
  [[noreturn]] void fail(const std::string& key, const YAML::Node& at, const std::string& expected,
                         const std::string& got = {}) const {
    std::string where = ctx_.origins ? ctx_.origins->where(key, "") : "";
    if (where.empty()) {
      const YAML::Mark m = at.Mark();
      where = m.line >= 0 ? ctx_.file + ":" + std::to_string(m.line + 1) : ctx_.file;
    }
    throw ConfigError(where, key, expected, got);
  }

 private:
  YAML::Node take(const std::string& key) {
    read_.insert(key);
    const YAML::Node n = node_[key];
    if (!n.IsDefined() || n.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
    return n;
  }
  static std::string scalar_text(const YAML::Node& n) { return n.IsScalar() ? n.Scalar() : "a non-scalar"; }
  void check_range(const std::string& key, const YAML::Node& n, double v, double lo, double hi) const {
    if (v < lo || v > hi) {
      std::ostringstream ss;
      if (hi == kInf)
        ss << "a value >= " << lo;
      else if (lo == -kInf)
        ss << "a value <= " << hi;
      else
        ss << "a value in [" << lo << ", " << hi << "]";
      fail(full(key), n, ss.str(), n.IsScalar() ? n.Scalar() : std::string());
    }
  }

  const YAML::Node node_;  // a handle; const so operator[] never inserts keys
  ReadContext ctx_;
  std::string path_;
  std::set<std::string> read_;
};

/// Runs `fn` on the map under `key` of `parent` if present.
inline void with_map(MapReader& parent, const std::string& key, const std::function<void(MapReader&)>& fn) {
  const YAML::Node n = parent.child(key);
  if (!n) return;
  MapReader r(n, parent.context(), parent.full(key));
  fn(r);
  r.finish();
}

}  // namespace pvb::scenes::detail
