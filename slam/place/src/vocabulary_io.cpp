// Vocabulary files: DBoW2's text format (ORB-SLAM2's ORBvoc.txt) and our
// binary format, told apart by the first bytes.
//
// Binary format (little-endian; docs/place_recognition.md, "Vocabulary"):
//   offset 0   8 bytes  magic "PVBVOC1\n"
//          8   u32      k
//         12   u32      L
//         16   u32      node count n, the root included
//         20   u32      word count (the leaves)
//         24   n - 1 node records of 45 bytes, nodes 1 .. n-1 in id order:
//                u32 parent id, u8 is_leaf (0 or 1), 32 bytes descriptor,
//                f64 weight (IEEE 754; the IDF for a leaf, 0 otherwise)
//   24 + 45 (n - 1)  u64 FNV-1a (64-bit) of every byte before it
#include <sys/stat.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <string_view>
#include <tuple>

#include "pvb/common/error.hpp"
#include "pvb/common/fnv.hpp"
#include "pvb/common/output_file.hpp"
#include "pvb/common/text.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "vocabulary_builder.hpp"

namespace pvb::slam::place {
namespace {

constexpr char kMagic[] = "PVBVOC1\n";  // 8 bytes, without the terminating NUL
constexpr std::size_t kMagicBytes = 8;
constexpr std::size_t kHeaderBytes = 24;
constexpr std::size_t kNodeBytes = 45;
constexpr std::size_t kChecksumBytes = 8;
constexpr std::size_t kTextFields = 35;  // parent, is_leaf, 32 bytes, weight

/// A file's bytes, read whole in one call into a buffer that is not
/// cleared first (a vocabulary file can be tens of megabytes).
struct FileBytes {
  std::unique_ptr<char[]> data;
  std::size_t size = 0;
  std::string_view view() const { return {data.get(), size}; }
};

FileBytes read_whole(const std::string& path) {
  require_regular_file(path);  // before the open: a FIFO would block it for ever
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  struct stat st {};
  if (fstat(fileno(f.get()), &st) != 0 || !S_ISREG(st.st_mode)) {
    throw IoError(path, "cannot read: not a regular file");
  }
  FileBytes bytes;
  bytes.size = static_cast<std::size_t>(st.st_size);
  bytes.data.reset(new char[bytes.size + 1]);
  if (bytes.size > 0 && std::fread(bytes.data.get(), 1, bytes.size, f.get()) != bytes.size) {
    throw IoError(path, std::string("cannot read: ") + std::strerror(errno));
  }
  return bytes;
}

// ---------------------------------------------------------------- binary

std::uint32_t get_u32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}
std::uint64_t get_u64(const unsigned char* p) {
  return static_cast<std::uint64_t>(get_u32(p)) | static_cast<std::uint64_t>(get_u32(p + 4)) << 32;
}
double get_f64(const unsigned char* p) {
  const std::uint64_t bits = get_u64(p);
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}
void put_u32(unsigned char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
void put_u64(unsigned char* p, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
void put_f64(unsigned char* p, double v) {
  std::uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  put_u64(p, bits);
}

IoError at_byte(const std::string& path, std::size_t offset, const std::string& what) {
  return IoError(path, "byte " + std::to_string(offset) + ": " + what);
}

/// Checks the magic, the header's ranges, the size and the checksum;
/// returns the node count.
std::uint32_t check_binary_frame(const std::string& path, const unsigned char* p, std::size_t size) {
  if (size < kMagicBytes) {
    throw IoError(path,
                  "truncated at byte " + std::to_string(size) + ": expected the 8-byte magic \"PVBVOC1\"");
  }
  if (std::memcmp(p, kMagic, kMagicBytes) != 0) {
    throw at_byte(path, 0, "expected the magic \"PVBVOC1\" (an unsupported version of the binary format?)");
  }
  if (size < kHeaderBytes) {
    throw IoError(path, "truncated at byte " + std::to_string(size) + ": expected a 24-byte header");
  }
  const std::uint32_t k = get_u32(p + 8), levels = get_u32(p + 12), nodes = get_u32(p + 16);
  const std::uint32_t words = get_u32(p + 20);
  if (k < 2 || k > 64) throw at_byte(path, 8, "k: expected an integer in [2, 64], got " + std::to_string(k));
  if (levels < 1 || levels > 8) {
    throw at_byte(path, 12, "L: expected an integer in [1, 8], got " + std::to_string(levels));
  }
  if (nodes < 2) throw at_byte(path, 16, "node count: expected at least 2, got " + std::to_string(nodes));
  if (words < 1 || words >= nodes) {
    throw at_byte(path, 20,
                  "word count: expected an integer in [1, node count), got " + std::to_string(words));
  }
  const std::size_t body = kHeaderBytes + kNodeBytes * (static_cast<std::size_t>(nodes) - 1);
  if (size < body + kChecksumBytes) {
    throw IoError(path, "truncated at byte " + std::to_string(size) + ": expected " +
                            std::to_string(body + kChecksumBytes) + " bytes for " + std::to_string(nodes) +
                            " nodes");
  }
  if (size > body + kChecksumBytes) {
    throw at_byte(path, body + kChecksumBytes,
                  "unexpected data after the checksum (the file has " + std::to_string(size) + " bytes)");
  }
  if (get_u64(p + body) != fnv1a64(p, body)) {
    throw at_byte(path, body, "checksum mismatch: the file is corrupt");
  }
  return nodes;
}

}  // namespace

/// The file formats, with access to the nodes.
struct VocabularyFiles {
  static Vocabulary load_binary(const std::string& path, std::string_view bytes) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
    const std::uint32_t n = check_binary_frame(path, p, bytes.size());
    Vocabulary voc;
    VocabularyBuilder::start(voc, static_cast<int>(get_u32(p + 8)), static_cast<int>(get_u32(p + 12)), n);
    std::vector<std::uint8_t> depth;
    depth.reserve(n);
    for (std::uint32_t id = 1; id < n; ++id) {
      const std::size_t off = kHeaderBytes + kNodeBytes * (id - 1);
      const unsigned char* r = p + off;
      if (r[4] > 1) throw at_byte(path, off + 4, "is_leaf: expected 0 or 1, got " + std::to_string(r[4]));
      const double weight = get_f64(r + 37);
      if (!std::isfinite(weight) || weight < 0) {
        throw at_byte(path, off + 37, "weight: expected a finite number >= 0");
      }
      const std::string err = VocabularyBuilder::append(voc, depth, get_u32(r), r[4] == 1, r + 5, weight);
      if (!err.empty()) throw at_byte(path, off, err);
    }
    if (voc.size() != get_u32(p + 20)) {
      throw at_byte(path, 20,
                    "word count " + std::to_string(get_u32(p + 20)) + ", but " + std::to_string(voc.size()) +
                        " nodes are leaves");
    }
    if (const NodeId bad = VocabularyBuilder::first_childless_inner_node(voc); bad != 0) {
      throw at_byte(path, kHeaderBytes + kNodeBytes * (bad - 1),
                    "node " + std::to_string(bad) + " is not a leaf but has no children");
    }
    VocabularyBuilder::lay_out(voc);
    return voc;
  }

  static std::string binary_bytes(const Vocabulary& voc) {
    const std::vector<VocabularyBuilder::Node>& nodes = VocabularyBuilder::nodes(voc);
    const std::size_t body = kHeaderBytes + kNodeBytes * (nodes.size() - 1);
    std::string bytes(body + kChecksumBytes, '\0');
    auto* p = reinterpret_cast<unsigned char*>(bytes.data());
    std::memcpy(p, kMagic, kMagicBytes);
    put_u32(p + 8, static_cast<std::uint32_t>(voc.k()));
    put_u32(p + 12, static_cast<std::uint32_t>(voc.levels()));
    put_u32(p + 16, static_cast<std::uint32_t>(nodes.size()));
    put_u32(p + 20, static_cast<std::uint32_t>(voc.size()));
    for (std::size_t id = 1; id < nodes.size(); ++id) {
      unsigned char* r = p + kHeaderBytes + kNodeBytes * (id - 1);
      put_u32(r, nodes[id].parent);
      r[4] = nodes[id].leaf ? 1 : 0;
      std::memcpy(r + 5, nodes[id].descriptor.data(), 32);
      put_f64(r + 37, nodes[id].weight);
    }
    put_u64(p + body, fnv1a64(p, body));
    return bytes;
  }

  static Vocabulary load_text(const std::string& path, std::string_view bytes);
  static std::string text(const Vocabulary& voc);
};

// ------------------------------------------------------------------ text

namespace {

/// Lines of a text file, numbered from 1, without their '\n' or a '\r'
/// before it.  A file ending with '\n' has no empty last line.
class Lines {
 public:
  explicit Lines(std::string_view bytes) : text_(bytes) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    if (end == std::string_view::npos) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

/// Splits on spaces and tabs into at most N fields; returns the count, or
/// N + 1 when there are more.
template <std::size_t N>
std::size_t split_fields(std::string_view line, std::array<std::string_view, N>& out) {
  std::size_t count = 0, i = 0;
  while (true) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    if (i >= line.size()) return count;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t') ++j;
    if (count == N) return N + 1;
    out[count++] = line.substr(i, j - i);
    i = j;
  }
}

template <typename T>
bool parse_whole(std::string_view s, T& v) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

std::string quoted(std::string_view s) { return "\"" + std::string(s.substr(0, 40)) + "\""; }

/// The header line: k and L in range, L1 scoring and TF-IDF weighting.
std::pair<int, int> parse_text_header(const std::string& path, Lines& lines) {
  std::string_view line;
  if (!lines.next(line)) {
    throw IoError(path, "empty file: expected the header line \"k L scoring weighting\"", 1);
  }
  std::array<std::string_view, 4> f;
  int k = 0, levels = 0, scoring = 0, weighting = 0;
  if (split_fields(line, f) != 4 || !parse_whole(f[0], k) || !parse_whole(f[1], levels) ||
      !parse_whole(f[2], scoring) || !parse_whole(f[3], weighting)) {
    throw IoError(path, "expected the header \"k L scoring weighting\" (4 integers), got " + quoted(line), 1);
  }
  if (k < 2 || k > 64) throw IoError(path, "k: expected an integer in [2, 64], got " + std::to_string(k), 1);
  if (levels < 1 || levels > 8) {
    throw IoError(path, "L: expected an integer in [1, 8], got " + std::to_string(levels), 1);
  }
  if (scoring != 0 || weighting != 0) {
    throw IoError(path,
                  "expected scoring 0 (L1) and weighting 0 (TF-IDF), got scoring " + std::to_string(scoring) +
                      " and weighting " + std::to_string(weighting),
                  1);
  }
  return {k, levels};
}

/// One node line; returns what is wrong with it, "" when nothing.
std::string parse_node_line(std::string_view line, NodeId& parent, bool& leaf,
                            std::array<unsigned char, 32>& desc, double& weight) {
  std::array<std::string_view, kTextFields> f;
  const std::size_t count = split_fields(line, f);
  if (count != kTextFields) {
    return "expected 35 fields (parent, is_leaf, 32 descriptor bytes, weight), got " +
           (count > kTextFields ? std::string("more") : std::to_string(count));
  }
  if (!parse_whole(f[0], parent)) return "parent: expected a node id, got " + quoted(f[0]);
  if (f[1] != "0" && f[1] != "1") return "is_leaf: expected 0 or 1, got " + quoted(f[1]);
  leaf = f[1] == "1";
  for (std::size_t i = 0; i < 32; ++i) {
    unsigned v = 256;
    if (!parse_whole(f[2 + i], v) || v > 255) {
      return "descriptor byte " + std::to_string(i) + ": expected an integer in [0, 255], got " +
             quoted(f[2 + i]);
    }
    desc[i] = static_cast<unsigned char>(v);
  }
  if (!parse_whole(f[34], weight) || !std::isfinite(weight) || weight < 0) {
    return "weight: expected a finite number >= 0, got " + quoted(f[34]);
  }
  return {};
}

/// Writes `w` as DBoW2 does (an ostream's default, %g with 6 digits) when
/// that reads back to the same double, else with the shortest digits that
/// do, so that text round trips are exact.
void append_weight(std::string& out, double w) {
  std::array<char, 64> buf;
  auto r = std::to_chars(buf.data(), buf.data() + buf.size(), w, std::chars_format::general, 6);
  double back = 0;
  if (!parse_whole(std::string_view(buf.data(), static_cast<std::size_t>(r.ptr - buf.data())), back) ||
      back != w) {
    r = std::to_chars(buf.data(), buf.data() + buf.size(), w);
  }
  out.append(buf.data(), r.ptr);
}

void append_uint(std::string& out, unsigned v) {
  std::array<char, 16> buf;
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  out.append(buf.data(), r.ptr);
}

}  // namespace

Vocabulary VocabularyFiles::load_text(const std::string& path, std::string_view bytes) {
  Lines lines(bytes);
  const auto [k, levels] = parse_text_header(path, lines);
  Vocabulary voc;
  VocabularyBuilder::start(voc, k, levels, bytes.size() / 90 + 2);
  std::vector<std::uint8_t> depth;
  std::string_view line;
  std::array<unsigned char, 32> desc{};
  while (lines.next(line)) {
    NodeId parent = 0;
    bool leaf = false;
    double weight = 0;
    std::string err = parse_node_line(line, parent, leaf, desc, weight);
    if (err.empty()) err = VocabularyBuilder::append(voc, depth, parent, leaf, desc.data(), weight);
    if (!err.empty()) throw IoError(path, err, lines.number());
  }
  if (voc.empty()) throw IoError(path, "no words: expected node lines after the header", lines.number() + 1);
  if (const NodeId bad = VocabularyBuilder::first_childless_inner_node(voc); bad != 0) {
    throw IoError(path, "node " + std::to_string(bad) + " is not a leaf (is_leaf 0) but has no children",
                  static_cast<int>(bad) + 1);
  }
  VocabularyBuilder::lay_out(voc);
  return voc;
}

std::string VocabularyFiles::text(const Vocabulary& voc) {
  const std::vector<VocabularyBuilder::Node>& nodes = VocabularyBuilder::nodes(voc);
  std::string out;
  out.reserve(nodes.size() * 110 + 16);
  // DBoW2's spacing: "k L  scoring weighting", and two spaces before the weight.
  out += std::to_string(voc.k()) + " " + std::to_string(voc.levels()) + "  0 0\n";
  for (std::size_t id = 1; id < nodes.size(); ++id) {
    append_uint(out, nodes[id].parent);
    out += nodes[id].leaf ? " 1 " : " 0 ";
    for (const unsigned char b : nodes[id].descriptor) {
      append_uint(out, b);
      out += ' ';
    }
    out += ' ';
    append_weight(out, nodes[id].weight);
    out += '\n';
  }
  return out;
}

Vocabulary Vocabulary::load(const std::string& path) {
  const FileBytes file = read_whole(path);
  const std::string_view bytes = file.view();
  // Binary when the file starts like the magic ("PVBVOC"; a text file
  // starts with a digit), so that a cut binary file is reported as one.
  const std::size_t n = std::min<std::size_t>(bytes.size(), 6);
  if (n > 0 && std::memcmp(bytes.data(), kMagic, n) == 0) return VocabularyFiles::load_binary(path, bytes);
  return VocabularyFiles::load_text(path, bytes);
}

std::shared_ptr<const Vocabulary> Vocabulary::load_shared(const std::string& path) {
  // The file as it is now: a save goes through a new file (another inode),
  // and a rewrite in place changes the size or the modification time.
  using Key = std::tuple<std::string, dev_t, ino_t, off_t, std::int64_t>;
  static std::mutex mutex;
  static Key cached_key;
  static std::shared_ptr<const Vocabulary> cached;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return std::make_shared<const Vocabulary>(load(path));  // load() says why
  const Key key{path, st.st_dev, st.st_ino, st.st_size,
                static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
  const std::lock_guard<std::mutex> lock(mutex);
  if (!cached || cached_key != key) {
    cached = std::make_shared<const Vocabulary>(load(path));
    cached_key = key;
  }
  return cached;
}

void Vocabulary::save_binary(const std::string& path) const {
  if (empty()) throw IoError(path, "cannot save an empty vocabulary");
  const std::string bytes = VocabularyFiles::binary_bytes(*this);
  write_file_via_temp(path, [&](OutputFile& out) { out.append(bytes); });
}

void Vocabulary::save_text(const std::string& path) const {
  if (empty()) throw IoError(path, "cannot save an empty vocabulary");
  const std::string text = VocabularyFiles::text(*this);
  write_file_via_temp(path, [&](OutputFile& out) { out.append(text); });
}

}  // namespace pvb::slam::place
