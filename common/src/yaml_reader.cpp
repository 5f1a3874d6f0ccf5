#include "pvb/common/yaml_reader.hpp"

#include <yaml-cpp/depthguard.h>

#include <cmath>
#include <map>
#include <sstream>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"

namespace pvb::yaml {
namespace {

/// yaml-cpp would decode the string "0.003" (or '2', "true") as a number
/// or a flag; a quoted scalar (tag "!") is a string, in JSON and in YAML.
bool plain_scalar(const YAML::Node& n, const ReadContext& /*ctx*/) { return n.IsScalar() && n.Tag() != "!"; }

int line_of(const YAML::Node& at) {
  const int line = at.Mark().line;
  return line >= 0 ? line + 1 : 0;
}

}  // namespace

std::string ReadContext::where(const std::string& key, const YAML::Node& at) const {
  std::string w = locator ? locator->locate(key) : "";
  if (!w.empty()) return w;
  const int line = line_of(at);
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

void ReadContext::fail(const std::string& key, const YAML::Node& at, const std::string& expected,
                       const std::string& got) const {
  if (errors == ErrorKind::kConfig) throw ConfigError(where(key, at), key, expected, got);
  const std::string message = key + ": expected " + expected + (got.empty() ? "" : ", got " + got);
  const std::string located = locator ? locator->locate(key) : "";
  if (!located.empty()) throw IoError(located, message);
  throw IoError(file, message, line_of(at));
}

void ReadContext::missing(const std::string& key, const YAML::Node& at) const {
  if (errors == ErrorKind::kConfig) fail(key, at, "a value (required)");
  throw IoError(file, key + ": missing", line_of(at));
}

std::string join(const std::string& path, const std::string& key) {
  if (path.empty()) return key;
  if (key.empty()) return path;
  return key[0] == '[' ? path + key : path + "." + key;
}

std::string shown(const YAML::Node& n, const ReadContext& ctx) {
  if (!ctx.json && !n.IsScalar()) return "a non-scalar";
  if (!n.IsScalar()) return n.IsNull() ? "null" : "a list or an object";
  return n.Tag() == "!" ? "the string \"" + n.Scalar() + "\"" : n.Scalar();
}

YAML::Node parse(const std::string& text, const ReadContext& ctx) {
  const std::string format = ctx.json ? "JSON" : "YAML";
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::DeepRecursion& e) {
    if (ctx.errors == ErrorKind::kIo)
      throw IoError(ctx.file, "not valid " + format + ": nested too deeply for the parser", e.mark.line + 1);
    throw ConfigError(ctx.file + ":" + std::to_string(e.mark.line + 1), "(syntax)",
                      format + " nested at most a few hundred levels deep",
                      "nesting too deep for the parser");
  } catch (const YAML::Exception& e) {
    if (ctx.errors == ErrorKind::kIo)
      throw IoError(ctx.file, "not valid " + format + ": " + e.msg, e.mark.line + 1);
    throw ConfigError(ctx.file + ":" + std::to_string(e.mark.line + 1), "(syntax)", "valid " + format, e.msg);
  }
  // A document that is not a map is refused by its reader as a whole.
  if (root.IsMap()) check_unique_keys(root, ctx);
  return root;
}

void check_unique_keys(const YAML::Node& n, const ReadContext& ctx, const std::string& path) {
  if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i)
      check_unique_keys(n[i], ctx, path + "[" + std::to_string(i) + "]");
    return;
  }
  if (!n.IsMap()) return;
  std::map<std::string, int> first_line;
  for (const auto& kv : n) {
    if (!kv.first.IsScalar()) continue;  // the reader names a non-scalar key
    const std::string key = kv.first.Scalar();
    const std::string full = join(path, key);
    const int line = line_of(kv.first);
    const auto [seen, fresh] = first_line.emplace(key, line);
    if (!fresh) {
      // The second key's own line, never a merged document's idea of it.
      ReadContext here = ctx;
      here.locator = nullptr;
      here.fail(full, kv.first,
                "each key once in its section (first given at line " + std::to_string(seen->second) + ")",
                "a second " + key);
    }
    check_unique_keys(kv.second, ctx, full);
  }
}

bool decode_number(const YAML::Node& n, const ReadContext& ctx, double* v) {
  return plain_scalar(n, ctx) && YAML::convert<double>::decode(n, *v) && std::isfinite(*v);
}

bool decode_integer(const YAML::Node& n, const ReadContext& ctx, long long* v) {
  return plain_scalar(n, ctx) && YAML::convert<long long>::decode(n, *v);
}

bool decode_seed(const YAML::Node& n, const ReadContext& ctx, std::uint64_t* v) {
  unsigned long long u = 0;
  if (!plain_scalar(n, ctx) || n.Scalar().empty() || n.Scalar()[0] == '-' ||
      !YAML::convert<unsigned long long>::decode(n, u))
    return false;
  *v = u;
  return true;
}

bool decode_boolean(const YAML::Node& n, const ReadContext& ctx, bool* v) {
  return plain_scalar(n, ctx) && YAML::convert<bool>::decode(n, *v);
}

MapReader::MapReader(const YAML::Node& node, const ReadContext& ctx, std::string path)
    : node_(node), ctx_(ctx), path_(std::move(path)) {
  if (!node_.IsMap()) fail(path_.empty() ? "(top level)" : path_, node_, "a mapping of keys");
}

bool MapReader::has(const std::string& key) const {
  asked_.insert(key);
  return node_[key].IsDefined() && !node_[key].IsNull();
}

double MapReader::number(const std::string& key, double def, double lo, double hi) {
  const YAML::Node n = take(key);
  if (!n) return def;
  double v = 0;
  if (!decode_number(n, ctx_, &v)) fail(full(key), n, "a number", shown(n, ctx_));
  check_range(key, n, v, lo, hi);
  return v;
}

int MapReader::integer(const std::string& key, int def, int lo, int hi) {
  const YAML::Node n = take(key);
  if (!n) return def;
  long long v = 0;
  if (!decode_integer(n, ctx_, &v)) fail(full(key), n, "an integer", shown(n, ctx_));
  check_range(key, n, static_cast<double>(v), lo, hi);
  return static_cast<int>(v);
}

std::uint64_t MapReader::seed(const std::string& key, std::uint64_t def) {
  const YAML::Node n = take(key);
  if (!n) return def;
  std::uint64_t v = 0;
  if (!decode_seed(n, ctx_, &v)) fail(full(key), n, "a non-negative integer", shown(n, ctx_));
  return v;
}

bool MapReader::boolean(const std::string& key, bool def) {
  const YAML::Node n = take(key);
  if (!n) return def;
  bool v = false;
  if (!decode_boolean(n, ctx_, &v)) fail(full(key), n, "true or false", shown(n, ctx_));
  return v;
}

std::string MapReader::string(const std::string& key, const std::string& def) {
  const YAML::Node n = take(key);
  if (!n) return def;
  if (!n.IsScalar()) fail(full(key), n, "a string");
  for (const char c : n.Scalar())
    if ((static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f)
      fail(full(key), n, "a string without control characters", printable(n.Scalar()));
  return n.Scalar();
}

std::string MapReader::text(const std::string& key, bool required) {
  const YAML::Node n = take(key);
  if (!n) {
    if (required) ctx_.missing(full(key), node_);
    return {};
  }
  if (!n.IsScalar() || n.Scalar().empty()) fail(full(key), n, "a non-empty string");
  return n.Scalar();
}

std::vector<double> MapReader::numbers(const std::string& key, std::size_t size, double lo, double hi) {
  const YAML::Node n = take(key);
  if (!n) return {};
  const std::string what = "a list of " + std::to_string(size) + " numbers";
  if (!n.IsSequence() || n.size() != size) fail(full(key), n, what);
  std::vector<double> out;
  for (std::size_t i = 0; i < size; ++i) {
    const std::string item = key + "[" + std::to_string(i) + "]";
    double v = 0;
    if (!decode_number(n[i], ctx_, &v)) fail(full(item), n[i], "a number", shown(n[i], ctx_));
    check_range(item, n[i], v, lo, hi);
    out.push_back(v);
  }
  return out;
}

void MapReader::keys(const std::vector<std::string>& known) {
  read_.insert(known.begin(), known.end());
  finish();
}

void MapReader::finish() const {
  for (const auto& kv : node_) {
    if (!kv.first.IsScalar()) fail(full("?"), kv.first, "a key name", "a list or a map as a key");
    const std::string key = kv.first.Scalar();
    // A null value is the default (absent), also for a key only asked about.
    if (read_.count(key) == 0 && !(asked_.count(key) && kv.second.IsNull())) {
      std::set<std::string> all = read_;
      all.insert(asked_.begin(), asked_.end());
      std::string known;
      for (const auto& k : all) known += (known.empty() ? "" : ", ") + k;
      fail(full(key), kv.first, "a known key (" + known + ")", "unknown key");
    }
  }
}

YAML::Node MapReader::take(const std::string& key) {
  read_.insert(key);
  const YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) return YAML::Node(YAML::NodeType::Undefined);
  return n;
}

void MapReader::check_range(const std::string& key, const YAML::Node& n, double v, double lo,
                            double hi) const {
  if (v >= lo && v <= hi) return;
  std::ostringstream ss;
  if (hi == kInf)
    ss << "a value >= " << lo;
  else if (lo == -kInf)
    ss << "a value <= " << hi;
  else
    ss << "a value in [" << lo << ", " << hi << "]";
  fail(full(key), n, ss.str(), n.IsScalar() ? n.Scalar() : std::string());
}

void with_map(MapReader& parent, const std::string& key, const std::function<void(MapReader&)>& fn) {
  const YAML::Node n = parent.child(key);
  if (!n) return;
  MapReader r(n, parent.context(), parent.full(key));
  fn(r);
  r.finish();
}

}  // namespace pvb::yaml
