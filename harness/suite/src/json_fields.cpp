#include "json_fields.hpp"

#include <yaml-cpp/depthguard.h>

#include <cmath>

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
  const std::string text = read_file(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    throw IoError(path, "not valid JSON: nested too deeply for the parser", e.mark.line + 1);
  } catch (const YAML::Exception& e) {
    throw IoError(path, "not valid JSON: " + e.msg, e.mark.line + 1);
  }
  if (!root.IsMap()) throw IoError(path, "expected a JSON object at the top level");
  return root;
}

void JsonFields::fail(const YAML::Node& at, const std::string& key, const std::string& what) const {
  const YAML::Mark m = at.Mark();
  throw IoError(path_, prefix_ + key + ": " + what, m.line >= 0 ? m.line + 1 : 0);
}

YAML::Node JsonFields::required(const YAML::Node& obj, const std::string& key) const {
  const YAML::Node n = obj[key];
  if (!n.IsDefined()) fail(obj, key, "missing");
  return n;
}

std::string JsonFields::shown(const YAML::Node& n) {
  if (!n.IsScalar()) return n.IsNull() ? "null" : "a list or an object";
  return n.Tag() == "!" ? "the string \"" + n.Scalar() + "\"" : n.Scalar();
}

double JsonFields::number(const YAML::Node& obj, const std::string& key, double lo, double hi,
                          const std::string& bound_name) const {
  return number_at(required(obj, key), key, lo, hi, bound_name);
}

double JsonFields::number_at(const YAML::Node& n, const std::string& key, double lo, double hi,
                             const std::string& bound_name) const {
  double v = 0;
  if (!is_plain_scalar(n) || !YAML::convert<double>::decode(n, v) || !std::isfinite(v))
    fail(n, key, "expected a number, got " + shown(n));
  if (v < lo || v > hi)
    fail(n, key, "expected a number" + range_text(lo, hi, false, bound_name) + ", got " + shown(n));
  return v;
}

int JsonFields::integer(const YAML::Node& obj, const std::string& key, long long lo, long long hi,
                        const std::string& bound_name) const {
  return integer_at(required(obj, key), key, lo, hi, bound_name);
}

int JsonFields::integer_at(const YAML::Node& n, const std::string& key, long long lo, long long hi,
                           const std::string& bound_name) const {
  long long v = 0;
  if (!is_plain_scalar(n) || !YAML::convert<long long>::decode(n, v) || v < INT_MIN || v > INT_MAX)
    fail(n, key, "expected an integer, got " + shown(n));
  if (v < lo || v > hi)
    fail(n, key,
         "expected an integer" + range_text(double(lo), double(hi), true, bound_name) + ", got " + shown(n));
  return static_cast<int>(v);
}

unsigned long long JsonFields::seed(const YAML::Node& obj, const std::string& key) const {
  const YAML::Node n = required(obj, key);
  unsigned long long v = 0;
  if (!is_plain_scalar(n) || n.Scalar().empty() || n.Scalar()[0] == '-' ||
      !YAML::convert<unsigned long long>::decode(n, v))
    fail(n, key, "expected a non-negative integer, got " + shown(n));
  return v;
}

std::string JsonFields::text(const YAML::Node& obj, const std::string& key) const {
  const YAML::Node n = required(obj, key);
  if (!n.IsScalar()) fail(n, key, "expected a string");
  return n.Scalar();
}

}  // namespace pvb::suite::detail
