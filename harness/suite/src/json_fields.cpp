#include "json_fields.hpp"

#include <cmath>
#include <cstdint>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::suite::detail {
namespace {

/// The range of a value for a message: " >= 0", " in [0, 1]",
/// " in [0, frames = 300]", " >= frame = 601".
std::string range_text(double lo, double hi, bool whole, const std::string& bound_name) {
  const std::string named = bound_name.empty() ? "" : bound_name + " = ";
  const auto num = [whole](double v) { return whole ? format_fixed(v, 0) : format_g(v); };
  const bool has_lo = std::isfinite(lo) && !(whole && lo <= double(INT_MIN));
  const bool has_hi = std::isfinite(hi) && !(whole && hi >= double(INT_MAX));
  if (has_lo && has_hi) return " in [" + num(lo) + ", " + named + num(hi) + "]";
  if (has_lo) return " >= " + named + num(lo);
  if (has_hi) return " <= " + named + num(hi);
  return "";
}

}  // namespace

YAML::Node load_json_object(const std::string& path) {
  const yaml::ReadContext ctx{path, nullptr, yaml::ErrorKind::kIo, true};
  YAML::Node root = yaml::parse(read_file(path), ctx);
  if (!root.IsMap()) throw IoError(path, "expected a JSON object at the top level");
  return root;
}

std::string JsonFields::name(const std::string& key) const {
  if (!key.empty()) return prefix_ + key;
  // The prefix's own object: "loss_events[0]." names loss_events[0].
  return !prefix_.empty() && prefix_.back() == '.' ? prefix_.substr(0, prefix_.size() - 1) : prefix_;
}

void JsonFields::fail(const YAML::Node& at, const std::string& key, const std::string& expected,
                      const std::string& got) const {
  ctx_.fail(name(key), at, expected, got);
}

void JsonFields::missing(const YAML::Node& at, const std::string& key) const { ctx_.missing(name(key), at); }

YAML::Node JsonFields::required(const YAML::Node& obj, const std::string& key) const {
  const YAML::Node n = obj[key];
  if (!n.IsDefined()) missing(obj, key);
  return n;
}

std::string JsonFields::shown(const YAML::Node& n) {
  static const yaml::ReadContext json{"", nullptr, yaml::ErrorKind::kIo, true};
  return yaml::shown(n, json);
}

double JsonFields::number(const YAML::Node& obj, const std::string& key, double lo, double hi,
                          const std::string& bound_name) const {
  return number_at(required(obj, key), key, lo, hi, bound_name);
}

double JsonFields::number_at(const YAML::Node& n, const std::string& key, double lo, double hi,
                             const std::string& bound_name) const {
  double v = 0;
  if (!yaml::decode_number(n, ctx_, &v)) fail(n, key, "a number", shown(n));
  if (v < lo || v > hi) fail(n, key, "a number" + range_text(lo, hi, false, bound_name), shown(n));
  return v;
}

int JsonFields::integer(const YAML::Node& obj, const std::string& key, long long lo, long long hi,
                        const std::string& bound_name) const {
  return integer_at(required(obj, key), key, lo, hi, bound_name);
}

int JsonFields::integer_at(const YAML::Node& n, const std::string& key, long long lo, long long hi,
                           const std::string& bound_name) const {
  long long v = 0;
  if (!yaml::decode_integer(n, ctx_, &v) || v < INT_MIN || v > INT_MAX) fail(n, key, "an integer", shown(n));
  if (v < lo || v > hi) fail(n, key, "an integer" + range_text(double(lo), double(hi), true, bound_name), shown(n));
  return static_cast<int>(v);
}

unsigned long long JsonFields::seed(const YAML::Node& obj, const std::string& key) const {
  const YAML::Node n = required(obj, key);
  std::uint64_t v = 0;
  if (!yaml::decode_seed(n, ctx_, &v)) fail(n, key, "a non-negative integer", shown(n));
  return v;
}

std::string JsonFields::text(const YAML::Node& obj, const std::string& key) const {
  const YAML::Node n = required(obj, key);
  if (!n.IsScalar()) fail(n, key, "a string");
  return n.Scalar();
}

}  // namespace pvb::suite::detail
