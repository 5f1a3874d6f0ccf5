#pragma once
// The strict reader of the YAML and JSON files pvbench reads: scenarios,
// campaigns and the metrics.json of earlier runs.  Every mistake is one
// error naming the file, the line, the full key ("camera.depth_noise.
// axial_scale", "sessions[2].mode"), what was expected and what was found:
// "FILE:LINE: KEY: expected EXPECTED, got GOT".  A key given twice in one
// mapping is refused (yaml-cpp keeps both and finds the first, so the second
// would go unread), and a MapReader refuses every key it did not read.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace pvb::yaml {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Where a key was written when the node's own line is not the answer: a
/// scenario merged from a derived file and its bases knows the file and
/// line of each of its keys (scenes' KeyOrigins).
class KeyLocator {
 public:
  virtual ~KeyLocator() = default;
  /// "FILE:LINE" of the full key (or of its nearest enclosing key), or ""
  /// when unknown.
  virtual std::string locate(const std::string& key) const = 0;
};

/// The error a mistake is: ConfigError for a file a person writes (a
/// scenario, a campaign), IoError for an output pvbench reads back
/// (metrics.json).  Both read "FILE:LINE: KEY: expected ..., got ...".
enum class ErrorKind { kConfig, kIo };

/// What every reader of one document shares.
struct ReadContext {
  std::string file;                     ///< the file given, as errors name it
  const KeyLocator* locator = nullptr;  ///< where keys were written; null: each node's line
  ErrorKind errors = ErrorKind::kConfig;
  bool json = false;  ///< JSON read by yaml-cpp (errors say "null", "a list or an object"); in JSON and YAML
                      ///< a quoted scalar is text, never a number or a flag

  /// "FILE:LINE" of `key`: the locator's answer, else the line of `at` in
  /// the file given, else the file alone.
  std::string where(const std::string& key, const YAML::Node& at) const;
  /// Throws the error of this kind for `key` (its full name) at `at`.
  [[noreturn]] void fail(const std::string& key, const YAML::Node& at, const std::string& expected,
                         const std::string& got = {}) const;
  /// A required key that is absent from the map `at`: "KEY: expected a
  /// value (required)" (IoError: "KEY: missing").
  [[noreturn]] void missing(const std::string& key, const YAML::Node& at) const;
};

/// `path.key`, or `key` at the top level.
std::string join(const std::string& path, const std::string& key);
/// A value as an error shows it: the scalar's text (a quoted one as
/// `the string "..."`), else what kind of node it is.
std::string shown(const YAML::Node& n, const ReadContext& ctx);

/// Parses `text` (of ctx.file): a syntax error names the line ("(syntax):
/// expected valid YAML, got ..."; JSON: "not valid JSON: ..."), then, when
/// the document is a map, every mapping in it is checked for keys given twice.
YAML::Node parse(const std::string& text, const ReadContext& ctx);
/// Refuses a key given twice in one mapping of `n` (and below), naming the
/// second one's line and the first's: "KEY: expected each key once in its
/// section (first given at line N), got a second KEY".
void check_unique_keys(const YAML::Node& n, const ReadContext& ctx, const std::string& path = "");

/// Scalar decoding, the same for every reader (false: not one).
bool decode_number(const YAML::Node& n, const ReadContext& ctx, double* v);  ///< finite
bool decode_integer(const YAML::Node& n, const ReadContext& ctx, long long* v);
bool decode_seed(const YAML::Node& n, const ReadContext& ctx, std::uint64_t* v);  ///< >= 0, 64 bits
bool decode_boolean(const YAML::Node& n, const ReadContext& ctx, bool* v);

/// Strict reader over one map: every key read is recorded, and finish()
/// refuses any key that was not.  Absent and null keys give the default.
class MapReader {
 public:
  /// `path` is the map's full key ("" at the top level).
  MapReader(const YAML::Node& node, const ReadContext& ctx, std::string path);
  virtual ~MapReader() = default;

  /// True when `key` is given (not null).  The key counts as one this map
  /// knows, for the list an unknown key's error gives, but not as read.
  bool has(const std::string& key) const;
  /// A finite number in [lo, hi].
  double number(const std::string& key, double def, double lo, double hi);
  int integer(const std::string& key, int def, int lo, int hi);
  std::uint64_t seed(const std::string& key, std::uint64_t def);
  bool boolean(const std::string& key, bool def);
  /// A string of text: no control characters (a quoted "\0" or "\x07" is
  /// one; a NUL would cut a scene's XML short) but tabs and line breaks.
  std::string string(const std::string& key, const std::string& def);
  /// A non-empty string; `required`: absent is an error.
  std::string text(const std::string& key, bool required);
  template <typename Enum>
  Enum choice(const std::string& key, Enum def, const std::vector<std::pair<std::string, Enum>>& options);
  /// A list of `size` numbers each in [lo, hi] (absent: empty).
  std::vector<double> numbers(const std::string& key, std::size_t size, double lo, double hi);

  /// The node under `key`, recorded as read (absent or null: an undefined node).
  YAML::Node child(const std::string& key) { return take(key); }
  /// The map this reader reads.
  const YAML::Node& node() const { return node_; }
  std::string full(const std::string& key) const { return join(path_, key); }
  const std::string& path() const { return path_; }
  const ReadContext& context() const { return ctx_; }

  /// Declares the keys this map may have and refuses any other now (before
  /// their values are read).
  void keys(const std::vector<std::string>& known);
  /// Refuses keys that were never read.
  void finish() const;
  /// Throws for `key` (its full name) at the key's line, else the node's.
  [[noreturn]] void fail(const std::string& key, const YAML::Node& at, const std::string& expected,
                         const std::string& got = {}) const {
    ctx_.fail(key, at, expected, got);
  }

 protected:
  YAML::Node take(const std::string& key);
  void check_range(const std::string& key, const YAML::Node& n, double v, double lo, double hi) const;

 private:
  const YAML::Node node_;  // a handle; const so operator[] never inserts keys
  ReadContext ctx_;
  std::string path_;
  std::set<std::string> read_;
  mutable std::set<std::string> asked_;  ///< keys has() was asked about: known, maybe not read
};

/// Runs `fn` on the map under `key` of `parent` if present, then finish().
void with_map(MapReader& parent, const std::string& key, const std::function<void(MapReader&)>& fn);

template <typename Enum>
Enum MapReader::choice(const std::string& key, Enum def,
                       const std::vector<std::pair<std::string, Enum>>& options) {
  const YAML::Node n = take(key);
  if (!n) return def;
  std::string names;
  for (const auto& o : options) names += (names.empty() ? "" : ", ") + o.first;
  if (!n.IsScalar()) fail(full(key), n, "one of " + names);
  for (const auto& o : options)
    if (o.first == n.Scalar()) return o.second;
  fail(full(key), n, "one of " + names, n.Scalar());
}

}  // namespace pvb::yaml
