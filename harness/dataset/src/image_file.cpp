#include "pvb/dataset/image_file.hpp"

#include <array>
#include <cctype>
#include <climits>
#include <cstdint>
#include <opencv2/imgcodecs.hpp>

#include "pvb/common/error.hpp"
#include "pvb/common/text.hpp"
#include "pvb/sensor/image_codec.hpp"

namespace pvb::dataset {
namespace {

// --- PNG: signature, then chunks (length, type, data, CRC-32) up to IEND ---

constexpr char kPngSignature[] = "\x89PNG\r\n\x1a\n";

/// CRC-32 of the PNG specification (ISO 3309, polynomial 0xEDB88320).
std::uint32_t png_crc(const char* data, std::size_t n) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < n; ++i) c = table[(c ^ static_cast<unsigned char>(data[i])) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

std::uint32_t big_endian32(const std::string& b, std::size_t pos) {
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(b[pos + k]);
  return v;
}

std::optional<std::string> png_damage(const std::string& b) {
  std::size_t pos = 8;  // after the signature
  for (bool first = true;; first = false) {
    if (b.size() - pos < 8) return std::string("truncated PNG: ends before its IEND chunk");
    const std::uint32_t length = big_endian32(b, pos);
    const std::string type = b.substr(pos + 4, 4);
    for (char c : type)
      if (!std::isalpha(static_cast<unsigned char>(c)))
        return "corrupt PNG: no chunk type at byte " + std::to_string(pos + 4);
    if (first && type != "IHDR") return std::string("corrupt PNG: the first chunk is not IHDR");
    if (length > 0x7FFFFFFFu) return "corrupt PNG: chunk " + type + " has an impossible length";
    if (b.size() - pos - 8 < static_cast<std::size_t>(length) + 4)
      return "truncated PNG: ends inside chunk " + type + ", before IEND";
    if (png_crc(b.data() + pos + 4, length + 4) != big_endian32(b, pos + 8 + length))
      return "corrupt PNG: chunk " + type + " fails its CRC check";
    if (type == "IEND") return std::nullopt;
    pos += 12 + static_cast<std::size_t>(length);
  }
}

// --- PNM (P1..P6): header numbers, then the raster ---

class PnmHeader {
 public:
  explicit PnmHeader(const std::string& b) : b_(b) {}
  /// Skips whitespace and '#' comments, then reads a decimal number (at most
  /// 9 digits); false when there is none.
  bool number(long long* v) {
    skip_space();
    int digits = 0;
    *v = 0;
    for (; pos_ < b_.size() && std::isdigit(static_cast<unsigned char>(b_[pos_])) && digits < 10;
         ++pos_, ++digits)
      *v = *v * 10 + (b_[pos_] - '0');
    return digits > 0 && digits < 10;
  }
  void skip_space() {
    while (pos_ < b_.size()) {
      if (b_[pos_] == '#') {
        while (pos_ < b_.size() && b_[pos_] != '\n') ++pos_;
      } else if (std::isspace(static_cast<unsigned char>(b_[pos_]))) {
        ++pos_;
      } else {
        break;
      }
    }
  }
  std::size_t pos() const { return pos_; }
  void set_pos(std::size_t p) { pos_ = p; }

 private:
  const std::string& b_;
  std::size_t pos_ = 2;  // after "Pn"
};

/// Samples present in an ASCII raster (P1: one digit each; P2, P3: numbers).
long long ascii_samples(const std::string& b, PnmHeader* h, bool bitmap, long long wanted) {
  long long n = 0;
  for (; n < wanted; ++n) {
    h->skip_space();
    if (h->pos() >= b.size() || !std::isdigit(static_cast<unsigned char>(b[h->pos()]))) break;
    std::size_t p = h->pos() + 1;
    if (!bitmap)
      while (p < b.size() && std::isdigit(static_cast<unsigned char>(b[p]))) ++p;
    h->set_pos(p);
  }
  return n;
}

std::optional<std::string> pnm_damage(const std::string& b) {
  const char kind = b[1];
  const bool bitmap = kind == '1' || kind == '4';
  PnmHeader h(b);
  long long width = 0, height = 0, maxval = 1;
  if (!h.number(&width) || !h.number(&height) || (!bitmap && !h.number(&maxval)))
    return std::string("truncated or corrupt PNM header (expected width, height") +
           (bitmap ? ")" : ", maxval)");
  if (width < 1 || height < 1 || maxval < 1 || maxval > 65535 || width * height > (1LL << 31))
    return "corrupt PNM header: " + std::to_string(width) + "x" + std::to_string(height) + ", maxval " +
           std::to_string(maxval);
  const long long channels = (kind == '3' || kind == '6') ? 3 : 1;
  if (kind <= '3') {
    const long long wanted = width * height * channels;
    const long long found = ascii_samples(b, &h, bitmap, wanted);
    if (found < wanted)
      return "truncated PNM: " + std::to_string(found) + " of " + std::to_string(wanted) + " samples";
    return std::nullopt;
  }
  // Binary raster: exactly one whitespace character after the header.
  const std::size_t raster = h.pos() + 1;
  const long long bytes =
      bitmap ? (width + 7) / 8 * height : width * height * channels * (maxval > 255 ? 2 : 1);
  const long long present = b.size() > raster ? static_cast<long long>(b.size() - raster) : 0;
  if (present < bytes)
    return "truncated PNM: " + std::to_string(present) + " of " + std::to_string(bytes) + " raster bytes";
  return std::nullopt;
}

}  // namespace

std::optional<std::string> image_damage(const std::string& bytes) {
  if (bytes.size() >= 8 && bytes.compare(0, 8, kPngSignature, 8) == 0) return png_damage(bytes);
  if (bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6' &&
      (bytes.size() == 2 || std::isspace(static_cast<unsigned char>(bytes[2])) || bytes[2] == '#'))
    return pnm_damage(bytes);
  return std::nullopt;
}

cv::Mat read_image(const std::string& path, int imread_flags, const std::string& what) {
  std::string bytes;
  try {
    bytes = read_file(path);
  } catch (const IoError&) {
    throw IoError(path, "missing or unreadable " + what);
  }
  if (bytes.empty() || bytes.size() > static_cast<std::size_t>(INT_MAX))
    throw IoError(path, "missing or unreadable " + what);
  if (const std::optional<std::string> why = image_damage(bytes))
    throw IoError(path, "damaged " + what + ": " + *why);
  cv::Mat image;
  try {
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8U, bytes.data());
    image = sensor::imdecode(buffer, imread_flags);
  } catch (const cv::Exception& e) {
    throw IoError(path, "unreadable " + what + ": " + e.err);
  }
  if (image.empty()) throw IoError(path, "missing or unreadable " + what);
  return image;
}

}  // namespace pvb::dataset
