// Vocabulary::train: hierarchical k-means++ with binary k-medians centres
// (DBoW2's HKmeansStep), breadth first, then the IDF weights.
#include <chrono>
#include <cmath>
#include <random>

#include "pvb/common/error.hpp"
#include "pvb/slam/place/vocabulary.hpp"
#include "vocabulary_builder.hpp"

namespace pvb::slam::place {
namespace {

constexpr const char* kWhat = "vocabulary training";

/// kSpread[v]: byte t of the result is bit t of v, so that adding it to a
/// 64-bit word counts the 8 bits of one descriptor byte in 8 byte lanes.
struct SpreadTable {
  std::array<std::uint64_t, 256> v{};
  SpreadTable() {
    for (unsigned b = 0; b < 256; ++b) {
      for (unsigned t = 0; t < 8; ++t) v[b] |= static_cast<std::uint64_t>((b >> t) & 1U) << (8 * t);
    }
  }
};
const SpreadTable kSpread;

/// The binary median of `members` (DBoW2's FORB::meanValue): a bit is set
/// when at least half of the members have it set (count >= ceil(n / 2)).
Bits256 binary_median(const std::vector<Bits256>& all, const std::vector<std::uint32_t>& members) {
  std::array<std::uint32_t, 256> counts{};  // [byte * 8 + bit]
  std::array<std::uint64_t, 32> lanes{};    // per byte, 8 byte-wide counters (at most 255 each)
  auto flush = [&] {
    for (std::size_t j = 0; j < 32; ++j) {
      for (std::size_t t = 0; t < 8; ++t) counts[j * 8 + t] += (lanes[j] >> (8 * t)) & 0xFFU;
      lanes[j] = 0;
    }
  };
  int pending = 0;
  for (const std::uint32_t m : members) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(all[m].data());
    for (std::size_t j = 0; j < 32; ++j) lanes[j] += kSpread.v[bytes[j]];
    if (++pending == 255) {
      flush();
      pending = 0;
    }
  }
  flush();
  std::array<unsigned char, 32> out{};
  const std::size_t n = members.size();
  for (std::size_t j = 0; j < 32; ++j) {
    for (std::size_t t = 0; t < 8; ++t) {
      if (2 * static_cast<std::size_t>(counts[j * 8 + t]) >= n) out[j] |= static_cast<unsigned char>(1U << t);
    }
  }
  return pack_descriptor(out.data());
}

struct Clusters {
  std::vector<Bits256> centres;
  std::vector<std::vector<std::uint32_t>> groups;  ///< indices into the descriptors, ascending
};

class KMedians {
 public:
  KMedians(const std::vector<Bits256>& all, const TrainParams& params) : all_(all), params_(params) {
    rng_.seed(params.seed);
  }

  /// Clusters `members` into at most k groups; the trivial case (at most k
  /// members) makes each member its own group, as DBoW2 does.
  Clusters run(const std::vector<std::uint32_t>& members) {
    Clusters c;
    if (members.size() <= static_cast<std::size_t>(params_.k)) {
      for (const std::uint32_t m : members) {
        c.centres.push_back(all_[m]);
        c.groups.push_back({m});
      }
      return c;
    }
    c.centres = seed_centres(members);
    std::vector<int> assignment(members.size(), -1);
    assign(members, c, assignment);
    for (int it = 0; it < params_.max_iterations; ++it) {
      // A centre left without members keeps its place (it may win some back).
      Clusters next{c.centres, {}};
      for (std::size_t g = 0; g < c.groups.size(); ++g) {
        if (!c.groups[g].empty()) next.centres[g] = binary_median(all_, c.groups[g]);
      }
      const bool changed = assign(members, next, assignment);
      c = std::move(next);  // as DBoW2: the medians of the last groups
      if (!changed) break;
    }
    drop_empty(c);
    return c;
  }

 private:
  /// k-means++ seeding: the first centre uniformly at random, each next one
  /// with probability proportional to the squared Hamming distance to the
  /// nearest centre so far.  Integer draws from the raw engine output (the
  /// same on every platform).  Fewer than k centres when the members hold
  /// fewer distinct descriptors.
  std::vector<Bits256> seed_centres(const std::vector<std::uint32_t>& members) {
    const std::size_t n = members.size();
    std::vector<Bits256> centres{all_[members[rng_() % n]]};
    std::vector<std::uint64_t> d2(n);
    for (std::size_t i = 0; i < n; ++i) d2[i] = sq(hamming(all_[members[i]], centres[0]));
    while (centres.size() < static_cast<std::size_t>(params_.k)) {
      std::uint64_t total = 0;
      for (const std::uint64_t v : d2) total += v;
      if (total == 0) break;
      const std::uint64_t cut = 1 + rng_() % total;
      std::uint64_t acc = 0;
      std::size_t pick = n - 1;
      for (std::size_t i = 0; i < n; ++i) {
        acc += d2[i];
        if (acc >= cut) {
          pick = i;  // d2[pick] > 0: never a copy of a centre
          break;
        }
      }
      centres.push_back(all_[members[pick]]);
      for (std::size_t i = 0; i < n; ++i)
        d2[i] = std::min(d2[i], sq(hamming(all_[members[i]], centres.back())));
    }
    return centres;
  }

  /// Assigns each member to its nearest centre (ties to the lowest index);
  /// true when some assignment changed.
  bool assign(const std::vector<std::uint32_t>& members, Clusters& c, std::vector<int>& assignment) const {
    c.groups.assign(c.centres.size(), {});
    bool changed = false;
    for (std::size_t i = 0; i < members.size(); ++i) {
      const Bits256& d = all_[members[i]];
      int best = 0;
      int best_dist = hamming(d, c.centres[0]);
      for (std::size_t g = 1; g < c.centres.size(); ++g) {
        const int dist = hamming(d, c.centres[g]);
        if (dist < best_dist) {
          best_dist = dist;
          best = static_cast<int>(g);
        }
      }
      changed = changed || assignment[i] != best;
      assignment[i] = best;
      c.groups[static_cast<std::size_t>(best)].push_back(members[i]);
    }
    return changed;
  }

  /// A centre can lose all its members to the others; it makes no child.
  static void drop_empty(Clusters& c) {
    std::size_t out = 0;
    for (std::size_t g = 0; g < c.groups.size(); ++g) {
      if (c.groups[g].empty()) continue;
      if (out != g) {  // no self-move: it would empty the group
        c.centres[out] = c.centres[g];
        c.groups[out] = std::move(c.groups[g]);
      }
      ++out;
    }
    c.centres.resize(out);
    c.groups.resize(out);
  }

  static std::uint64_t sq(int d) { return static_cast<std::uint64_t>(d) * static_cast<std::uint64_t>(d); }

  const std::vector<Bits256>& all_;
  const TrainParams& params_;
  std::mt19937_64 rng_;
};

void check_params(const TrainParams& p) {
  if (p.k < 2 || p.k > 64) throw ConfigError(kWhat, "k", "an integer in [2, 64]", std::to_string(p.k));
  if (p.levels < 1 || p.levels > 8) {
    throw ConfigError(kWhat, "levels", "an integer in [1, 8]", std::to_string(p.levels));
  }
  if (p.max_iterations < 0) {
    throw ConfigError(kWhat, "max_iterations", "an integer >= 0", std::to_string(p.max_iterations));
  }
}

/// The descriptors of all images, and where each non-empty image's begin.
struct Training {
  std::vector<Bits256> all;
  std::vector<std::size_t> image_begin;  ///< plus all.size() at the end
};

Training gather(const std::vector<cv::Mat>& per_image) {
  Training t;
  for (std::size_t i = 0; i < per_image.size(); ++i) {
    const cv::Mat& m = per_image[i];
    if (m.empty()) continue;
    if (m.type() != CV_8U || m.cols != 32) {
      throw ConfigError(kWhat, "descriptors of image " + std::to_string(i), "CV_8U, N x 32 (256-bit ORB)",
                        "type " + std::to_string(m.type()) + ", " + std::to_string(m.rows) + " x " +
                            std::to_string(m.cols));
    }
    t.image_begin.push_back(t.all.size());
    for (int r = 0; r < m.rows; ++r) t.all.push_back(pack_descriptor(m.ptr<unsigned char>(r)));
  }
  if (t.all.empty()) throw ConfigError(kWhat, "descriptors", "at least one descriptor", "none");
  if (t.all.size() > 0xFFFFFFFFULL) throw ConfigError(kWhat, "descriptors", "at most 2^32 - 1", "more");
  t.image_begin.push_back(t.all.size());
  return t;
}

}  // namespace

/// The tree, level by level: every node of depth d - 1 with more than one
/// descriptor is split before any node of depth d, so that node ids are
/// breadth-first and a node's children consecutive.
struct TreeTrainer {
  static void build(Vocabulary& voc, const std::vector<Bits256>& all, const TrainParams& params) {
    using Node = VocabularyBuilder::Node;
    std::vector<Node>& nodes = VocabularyBuilder::nodes(voc);
    KMedians kmedians(all, params);
    struct Pending {
      NodeId id;
      std::vector<std::uint32_t> members;
    };
    std::vector<Pending> level(1);
    level[0].id = 0;
    level[0].members.resize(all.size());
    for (std::uint32_t i = 0; i < all.size(); ++i) level[0].members[i] = i;
    for (int depth = 1; depth <= params.levels && !level.empty(); ++depth) {
      std::vector<Pending> next;
      for (Pending& p : level) {
        Clusters c = kmedians.run(p.members);
        std::vector<std::uint32_t>().swap(p.members);  // free as we go
        for (std::size_t g = 0; g < c.centres.size(); ++g) {
          const auto id = static_cast<NodeId>(nodes.size());
          Node& n = nodes.emplace_back();
          n.parent = p.id;
          std::memcpy(n.descriptor.data(), c.centres[g].data(), n.descriptor.size());
          nodes[p.id].children.push_back(id);
          if (depth < params.levels && c.groups[g].size() > 1) next.push_back({id, std::move(c.groups[g])});
        }
      }
      level = std::move(next);
    }
  }

  /// IDF: ln(N / N_i), N the non-empty images and N_i those with a
  /// descriptor that transform() puts in word i (0 when none, as DBoW2).
  static void set_idf(Vocabulary& voc, const Training& t) {
    std::vector<VocabularyBuilder::Node>& nodes = VocabularyBuilder::nodes(voc);
    const std::size_t images = t.image_begin.size() - 1;
    std::vector<std::uint32_t> images_with(voc.size(), 0);
    std::vector<std::size_t> last_image(voc.size(), images);  // dedup per image
    for (std::size_t img = 0; img < images; ++img) {
      for (std::size_t i = t.image_begin[img]; i < t.image_begin[img + 1]; ++i) {
        const auto* bytes = reinterpret_cast<const unsigned char*>(t.all[i].data());
        const WordId w = voc.word_of(bytes);
        if (last_image[w] != img) {
          last_image[w] = img;
          ++images_with[w];
        }
      }
    }
    for (WordId w = 0; w < voc.size(); ++w) {
      nodes[voc.word_node(w)].weight =
          images_with[w] > 0 ? std::log(static_cast<double>(images) / images_with[w]) : 0.0;
    }
  }
};

Vocabulary Vocabulary::train(const std::vector<cv::Mat>& descriptors_per_image, const TrainParams& params,
                             TrainReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  check_params(params);
  const Training t = gather(descriptors_per_image);
  Vocabulary voc;
  VocabularyBuilder::start(voc, params.k, params.levels, 0);
  TreeTrainer::build(voc, t.all, params);
  voc.nodes_.shrink_to_fit();
  VocabularyBuilder::mark_leaves_as_words(voc);
  VocabularyBuilder::lay_out(voc);
  TreeTrainer::set_idf(voc, t);
  if (report != nullptr) {
    report->images = t.image_begin.size() - 1;
    report->descriptors = t.all.size();
    report->nodes = voc.node_count();
    report->words = voc.size();
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return voc;
}

}  // namespace pvb::slam::place
