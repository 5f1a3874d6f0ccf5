#pragma once
// A scenario file as a YAML document, with what it derives from resolved:
// the file and its bases (base: FILE) are read, checked one by one (size,
// nesting, keys given twice, which keys a derived file may change) and
// merged, the derived file's values over its base's.  Every key of the
// merged document remembers the file and line it was written on, so that
// an error in a value found in a base names the base.
#include <yaml-cpp/yaml.h>

#include <map>
#include <string>
#include <vector>

#include "pvb/common/yaml_reader.hpp"

namespace pvb::scenes::detail {

/// Where a key was written: its file, line (1-based) and how many bases
/// away from the file given (0: that file, 1: its base, ...).
struct KeyOrigin {
  std::string file;
  int line = 0;
  int depth = 0;
};

/// The origin of every key of a document, by its full path ("route.aisle",
/// "pv_arrays[1].dirt"; "pv_arrays[1]" is the list item itself).  The
/// reader's errors name the line a key was written on through it.
class KeyOrigins : public yaml::KeyLocator {
 public:
  std::string locate(const std::string& key) const override { return where(key, ""); }
  void set(const std::string& key, const KeyOrigin& origin) { map_[key] = origin; }
  const KeyOrigin* find(const std::string& key) const;
  /// Forgets `key` and everything below it (key.*, key[*]).
  void erase_below(const std::string& key);
  /// Takes the origins of `key` and everything below it from `from`.
  void copy_below(const KeyOrigins& from, const std::string& key);
  /// "FILE:LINE" of `key`, or of the nearest enclosing key that is known,
  /// or `fallback` when none is.
  std::string where(const std::string& key, const std::string& fallback) const;

 private:
  std::map<std::string, KeyOrigin> map_;
};

/// A key that a derived file gave but only a station file may, and the
/// "FILE:LINE" it was written at.
struct StationKey {
  std::string key;
  std::string where;
};

struct ScenarioDocument {
  YAML::Node root;                 ///< the merged document (a map)
  KeyOrigins origins;              ///< of every key of `root`
  std::string file;                ///< the file given ("origin" of in-memory text)
  std::vector<std::string> bases;  ///< the files it derives from, nearest first
  /// Keys a derived file gave that belong to the station; refused by
  /// refuse_station_keys() once the reader has named any unknown key.
  std::vector<StationKey> station_keys;
};

/// Throws ConfigError for the first of doc.station_keys (none: nothing).
void refuse_station_keys(const ScenarioDocument& doc);

/// Reads `path` and every base it names.  Throws ConfigError or IoError
/// naming the file, the line and the key.
ScenarioDocument load_document(const std::string& path);
/// The same from text; `origin` names it in errors, and a base is taken
/// relative to its folder.
ScenarioDocument parse_document(const std::string& text, const std::string& origin);

/// A scenario file's largest size.
inline constexpr std::size_t kMaxScenarioBytes = 1024 * 1024;

}  // namespace pvb::scenes::detail
