#pragma once
// Typed errors shared by every layer.  They are thrown for configuration and
// I/O problems only; ordinary outcomes (tracking lost, end of stream, solver
// not converged) are return values.  Only the apps catch them: they print
// what() as one line and exit non-zero.
#include <stdexcept>
#include <string>

namespace pvb {

/// Base of every error the project throws on purpose.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A configuration value is missing, of the wrong type or out of range.
/// what() reads "FILE: KEY: expected EXPECTED[, got GOT]".
class ConfigError : public Error {
 public:
  ConfigError(std::string file, std::string key, std::string expected, std::string got = {});
  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }

 private:
  std::string file_;
  std::string key_;
};

/// A file could not be read or written, or its content is malformed.
/// what() reads "FILE[:LINE]: MESSAGE".
class IoError : public Error {
 public:
  IoError(std::string file, std::string message, int line = 0);
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  /// The message without the file and line.
  const std::string& message() const { return message_; }

 private:
  std::string file_;
  std::string message_;
  int line_;
};

/// A run-time facility (a GL backend, a device) is not available.
class UnavailableError : public Error {
 public:
  using Error::Error;
};

/// Library version string (CMake project version).
const char* version();

}  // namespace pvb
