#include "pvb/common/error.hpp"

namespace pvb {
namespace {
std::string config_message(const std::string& file, const std::string& key, const std::string& expected,
                           const std::string& got) {
  // A message without a key (an option's own value) reads "FILE: expected ...".
  std::string msg = file + ": " + (key.empty() ? std::string() : key + ": ") + "expected " + expected;
  if (!got.empty()) msg += ", got " + got;
  return msg;
}
std::string io_message(const std::string& file, const std::string& message, int line) {
  return file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + message;
}
}  // namespace

ConfigError::ConfigError(std::string file, std::string key, std::string expected, std::string got)
    : Error(config_message(file, key, expected, got)), file_(std::move(file)), key_(std::move(key)) {}

IoError::IoError(std::string file, std::string message, int line)
    : Error(io_message(file, message, line)),
      file_(std::move(file)),
      message_(std::move(message)),
      line_(line) {}

const char* version() { return PVB_VERSION; }

}  // namespace pvb
