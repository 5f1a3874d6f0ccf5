#pragma once
// Small text and file helpers used across layers.
#include <string>
#include <vector>

namespace pvb {

/// Throws IoError naming `path` unless it is a regular file (or a link to
/// one).  Checked with stat before anything opens it: a FIFO would block an
/// open for reading, and a folder opens but reads as garbage.
void require_regular_file(const std::string& path);
/// Reads a whole regular file; throws IoError when it cannot.
std::string read_file(const std::string& path);
/// `s` made safe for one line of a message: control characters, DEL and
/// bytes that are not UTF-8 become \xNN (a tab \t, a newline \n).
std::string printable(const std::string& s);
/// Writes a whole file through `path`.tmp, renamed over `path` once whole
/// (write_file_via_temp); throws IoError naming `path` when it cannot, and
/// leaves neither a half-written file nor the temporary one behind.
void write_file(const std::string& path, const std::string& content);
/// Splits on any run of the given separator characters, skipping empty fields.
std::vector<std::string> split_ws(const std::string& line, const char* seps = " \t\r,");
/// Escapes a string for a JSON string literal (without the quotes).
std::string json_escape(const std::string& s);
/// The JSON string literal of `s`: quoted and escaped.
std::string json_string(const std::string& s);
/// `s` safe in HTML text and attribute values (<, >, & and ").
std::string html_escape(const std::string& s);
/// A JSON number with `significant_digits` digits (%.Ng); null when not finite.
std::string json_number(double v, int significant_digits = 17);

/// One number through a printf format with one double conversion, e.g.
/// format_number("%.2f mm", 3.14159) = "3.14 mm".
std::string format_number(const char* printf_format, double v);
/// `significant_digits` significant digits (%.Ng): format_g(0.0123456) = "0.0123456".
std::string format_g(double v, int significant_digits = 6);
/// The fewest significant digits (at least 6) that read back as `v` exactly:
/// format_exact(55.0000001) = "55.0000001", format_exact(55) = "55", so a
/// value just outside a limit is never printed as the limit.
std::string format_exact(double v);
/// %.9g with a point, so that YAML 1.1 (Python's yaml, Kalibr) and OpenCV's
/// FileStorage read it as a real: format_real(170) = "170.0",
/// format_real(2e-05) = "2.0e-05".
std::string format_real(double v);
/// `decimals` digits after the point (%.Nf): format_fixed(2.5, 2) = "2.50".
std::string format_fixed(double v, int decimals);

}  // namespace pvb
