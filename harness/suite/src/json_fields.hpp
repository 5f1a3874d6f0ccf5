#pragma once
// Checked fields of the JSON files pvbench reads back (metrics.json,
// campaign.json), read with the project's strict reader
// (pvb/common/yaml_reader.hpp, which parses JSON with yaml-cpp).  Every
// mistake is an IoError naming the file, the line and the key, a key given
// twice in one object is refused; a quoted number is a string, NaN and
// infinities are not numbers, and a value outside its range is refused
// rather than averaged.  Keys the reader does not know are left alone: a
// metrics.json holds far more than what is read back.
#include <yaml-cpp/yaml.h>

#include <climits>
#include <limits>
#include <string>

#include "pvb/common/yaml_reader.hpp"

namespace pvb::suite::detail {

/// Reads `path` (a regular file) as a JSON object, each key once in its
/// object; IoError when it is not one.
/// Keep the node non-const: a const node's missing key is an invalid node
/// that throws when asked its type.
YAML::Node load_json_object(const std::string& path);

class JsonFields {
 public:
  /// `prefix` names nested keys in errors ("baseline.", "sessions[2].").
  JsonFields(std::string path, std::string prefix)
      : ctx_{std::move(path), nullptr, yaml::ErrorKind::kIo, true}, prefix_(std::move(prefix)) {}

  const std::string& path() const { return ctx_.file; }
  const std::string& prefix() const { return prefix_; }
  /// The same file, keys under `more` ("loss_events[0].").
  JsonFields nested(const std::string& more) const { return JsonFields(ctx_.file, prefix_ + more); }

  /// "FILE:LINE: PREFIX.KEY: expected EXPECTED[, got GOT]" (key "": the prefix's own object).
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& expected,
                         const std::string& got = {}) const;
  /// "FILE:LINE: PREFIX.KEY: missing", at the line of the object `at`.
  [[noreturn]] void missing(const YAML::Node& at, const std::string& key) const;
  YAML::Node required(const YAML::Node& obj, const std::string& key) const;

  /// yaml-cpp reads JSON, and would decode the string "0.003" as a number:
  /// a quoted scalar (tag "!") is a string, never a number.
  static bool is_plain_scalar(const YAML::Node& n) { return n.IsScalar() && n.Tag() != "!"; }
  /// A value as a message shows it: a string in quotes.
  static std::string shown(const YAML::Node& n);

  /// A finite number in [lo, hi]; `bound_name` names the bound that comes
  /// from another field ("frames"; the upper one when both are finite).
  double number(const YAML::Node& obj, const std::string& key,
                double lo = -std::numeric_limits<double>::infinity(),
                double hi = std::numeric_limits<double>::infinity(),
                const std::string& bound_name = "") const;
  /// The same for the value `n` itself, named `key` (a list's item).
  double number_at(const YAML::Node& n, const std::string& key,
                   double lo = -std::numeric_limits<double>::infinity(),
                   double hi = std::numeric_limits<double>::infinity(),
                   const std::string& bound_name = "") const;
  /// A number in [0, 1].
  double share(const YAML::Node& obj, const std::string& key) const { return number(obj, key, 0.0, 1.0); }
  /// A whole number in [lo, hi].
  int integer(const YAML::Node& obj, const std::string& key, long long lo = INT_MIN, long long hi = INT_MAX,
              const std::string& bound_name = "") const;
  int integer_at(const YAML::Node& n, const std::string& key, long long lo = INT_MIN, long long hi = INT_MAX,
                 const std::string& bound_name = "") const;
  /// A whole number >= 0 that fits 64 bits (a seed).
  unsigned long long seed(const YAML::Node& obj, const std::string& key) const;
  std::string text(const YAML::Node& obj, const std::string& key) const;
  /// True when obj[key] is absent or null.
  static bool absent(const YAML::Node& obj, const std::string& key) {
    const YAML::Node n = obj[key];
    return !n.IsDefined() || n.IsNull();
  }

 private:
  /// The full key: the prefix, then `key`.
  std::string name(const std::string& key) const;

  yaml::ReadContext ctx_;
  std::string prefix_;
};

}  // namespace pvb::suite::detail
