#pragma once
// Small text and file helpers used across layers.
#include <string>
#include <vector>

namespace pvb {

/// Reads a whole file; throws IoError when it cannot.
std::string read_file(const std::string& path);
/// Writes a whole file atomically enough for our use (write then rename);
/// throws IoError when it cannot.
void write_file(const std::string& path, const std::string& content);
/// Splits on any run of the given separator characters, skipping empty fields.
std::vector<std::string> split_ws(const std::string& line, const char* seps = " \t\r,");
/// Escapes a string for a JSON string literal (without the quotes).
std::string json_escape(const std::string& s);
/// A JSON number with `significant_digits` digits (%.Ng); null when not finite.
std::string json_number(double v, int significant_digits = 17);

}  // namespace pvb
