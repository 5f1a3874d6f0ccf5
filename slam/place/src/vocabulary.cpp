// Vocabulary: descending the tree (transform, word_of), the L1 score, and
// the builder that training and the file readers fill the tree through.
#include "pvb/slam/place/vocabulary.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pvb/common/error.hpp"
#include "pvb/common/fnv.hpp"
#include "vocabulary_builder.hpp"

namespace pvb::slam::place {

void VocabularyBuilder::start(Vocabulary& voc, int k, int levels, std::size_t expected_nodes) {
  voc.k_ = k;
  voc.levels_ = levels;
  voc.nodes_.clear();
  voc.words_.clear();
  voc.branches_.clear();
  voc.root_children_ = 0;
  voc.nodes_.reserve(expected_nodes);
  voc.nodes_.emplace_back();
  voc.nodes_.back().children.reserve(static_cast<std::size_t>(k));
}

std::string VocabularyBuilder::append(Vocabulary& voc, std::vector<std::uint8_t>& depth, NodeId parent,
                                      bool leaf, const unsigned char* descriptor, double weight) {
  const auto id = static_cast<NodeId>(voc.nodes_.size());
  if (depth.empty()) depth.push_back(0);  // the root
  if (parent >= id) {
    return "parent " + std::to_string(parent) + " of node " + std::to_string(id) +
           ": expected an earlier node";
  }
  Node& p = voc.nodes_[parent];
  if (p.leaf) return "parent " + std::to_string(parent) + " of node " + std::to_string(id) + " is a leaf";
  if (p.children.size() >= static_cast<std::size_t>(voc.k_)) {
    return "node " + std::to_string(parent) + " has more than k = " + std::to_string(voc.k_) + " children";
  }
  const int d = depth[parent] + 1;
  if (d > voc.levels_) {
    return "node " + std::to_string(id) + " is at depth " + std::to_string(d) +
           ", deeper than L = " + std::to_string(voc.levels_);
  }
  p.children.push_back(id);
  depth.push_back(static_cast<std::uint8_t>(d));
  Node& n = voc.nodes_.emplace_back();
  n.parent = parent;
  std::memcpy(n.descriptor.data(), descriptor, n.descriptor.size());
  n.weight = weight;
  n.leaf = leaf;
  if (leaf) {
    n.word = static_cast<WordId>(voc.words_.size());
    voc.words_.push_back(id);
  } else {
    n.children.reserve(static_cast<std::size_t>(voc.k_));
  }
  return {};
}

void VocabularyBuilder::mark_leaves_as_words(Vocabulary& voc) {
  voc.words_.clear();
  for (NodeId id = 0; id < voc.nodes_.size(); ++id) {
    Node& n = voc.nodes_[id];
    n.leaf = id != 0 && n.children.empty();
    if (n.leaf) {
      n.word = static_cast<WordId>(voc.words_.size());
      voc.words_.push_back(id);
    }
  }
}

void VocabularyBuilder::lay_out(Vocabulary& voc) {
  const std::vector<Node>& nodes = voc.nodes_;
  std::vector<std::uint32_t> first(nodes.size() + 1, 0);  // where each node's children go
  for (std::size_t id = 0; id < nodes.size(); ++id) {
    first[id + 1] = first[id] + static_cast<std::uint32_t>(nodes[id].children.size());
  }
  voc.branches_.assign(first.back(), {});
  for (std::size_t id = 0; id < nodes.size(); ++id) {
    std::uint32_t i = first[id];
    for (const NodeId c : nodes[id].children) {
      Vocabulary::Branch& b = voc.branches_[i++];
      b.bits = pack_descriptor(nodes[c].descriptor.data());
      b.first = first[c];
      b.last = first[c + 1];
      b.node = c;
    }
  }
  voc.root_children_ = first[1];
}

NodeId VocabularyBuilder::first_childless_inner_node(const Vocabulary& voc) {
  for (NodeId id = 0; id < voc.nodes_.size(); ++id) {
    if (!voc.nodes_[id].leaf && voc.nodes_[id].children.empty()) return id;
  }
  return 0;
}

namespace {

void check_descriptors(const cv::Mat& descriptors) {
  if (descriptors.empty()) return;
  if (descriptors.type() != CV_8U || descriptors.cols != 32) {
    throw ConfigError("descriptors", "type", "CV_8U, N x 32 (256-bit ORB)",
                      "type " + std::to_string(descriptors.type()) + ", " + std::to_string(descriptors.rows) +
                          " x " + std::to_string(descriptors.cols));
  }
}

}  // namespace

WordId Vocabulary::word_of(const unsigned char* descriptor, double* weight, NodeId* node_at_level,
                           int levels_up) const {
  if (empty()) throw std::logic_error("Vocabulary::word_of on an empty vocabulary");
  const Bits256 d = pack_descriptor(descriptor);
  const int level_wanted = levels_ - levels_up;  // depth of the direct index's node
  NodeId at_level = 0;                           // the root, when level_wanted <= 0
  NodeId id = 0;
  int depth = 0;
  // Leaves, and only they, have no children (the loaders check it).
  for (std::uint32_t first = 0, last = root_children_; first != last;) {
    std::uint32_t best = first;
    int best_dist = hamming(d, branches_[first].bits);
    for (std::uint32_t i = first + 1; i < last; ++i) {
      const int dist = hamming(d, branches_[i].bits);
      if (dist < best_dist) {  // ties keep the first child
        best_dist = dist;
        best = i;
      }
    }
    const Branch& b = branches_[best];
    id = b.node;
    first = b.first;
    last = b.last;
    if (++depth == level_wanted) at_level = id;
  }
  if (depth < level_wanted) at_level = id;  // the path ended above the wanted depth
  if (weight != nullptr) *weight = nodes_[id].weight;
  if (node_at_level != nullptr) *node_at_level = at_level;
  return nodes_[id].word;
}

void Vocabulary::transform(const cv::Mat& descriptors, BowVector* bow, FeatureVector* fv,
                           int levels_up) const {
  check_descriptors(descriptors);
  if (bow != nullptr) bow->clear();
  if (fv != nullptr) fv->clear();
  if (empty() || descriptors.empty()) return;
  struct Hit {
    WordId word;
    NodeId node;
    std::uint32_t row;
    double weight;
  };
  std::vector<Hit> hits;
  hits.reserve(static_cast<std::size_t>(descriptors.rows));
  for (int i = 0; i < descriptors.rows; ++i) {
    Hit h{0, 0, static_cast<std::uint32_t>(i), 0};
    h.word = word_of(descriptors.ptr<unsigned char>(i), &h.weight, &h.node, levels_up);
    if (h.weight <= 0) continue;  // a stop word (IDF 0: in every training image), as DBoW2 skips it
    hits.push_back(h);
  }
  if (fv != nullptr) {
    // By node, each node's rows in ascending order (stable).
    std::stable_sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.node < b.node; });
    for (const Hit& h : hits) {
      if (fv->empty() || fv->back().first != h.node) fv->emplace_back(h.node, std::vector<std::uint32_t>{});
      fv->back().second.push_back(h.row);
    }
  }
  // TF-IDF: the IDF once per occurrence, summed per word in row order, as a
  // std::map's v[word] += weight would, so the sums are the same doubles.
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
    return a.word != b.word ? a.word < b.word : a.row < b.row;
  });
  BowVector local;
  BowVector& v = bow != nullptr ? *bow : local;
  for (const Hit& h : hits) {
    if (v.empty() || v.back().first != h.word) v.emplace_back(h.word, 0.0);
    v.back().second += h.weight;
  }
  double norm = 0;
  for (const auto& [word, w] : v) norm += std::fabs(w);
  if (norm > 0) {
    for (auto& [word, w] : v) w /= norm;
  }
}

std::uint64_t Vocabulary::fingerprint() const {
  const std::int32_t shape[2] = {k_, levels_};
  std::uint64_t h = fnv1a64(shape, sizeof shape);
  for (const Node& n : nodes_) {
    const std::uint8_t leaf = n.leaf ? 1 : 0;
    h = fnv1a64(&n.parent, sizeof n.parent, h);
    h = fnv1a64(&leaf, 1, h);
    h = fnv1a64(n.descriptor.data(), n.descriptor.size(), h);
    h = fnv1a64(&n.weight, sizeof n.weight, h);
  }
  return h;
}

double Vocabulary::score(const BowVector& a, const BowVector& b) {
  // DBoW2's L1Scoring: sum over common words of |a_i - b_i| - |a_i| - |b_i|,
  // times -1/2; for L1-normalised vectors 1 - 0.5 |a - b|_1.
  double sum = 0;
  auto ia = a.begin();
  auto ib = b.begin();
  while (ia != a.end() && ib != b.end()) {
    if (ia->first == ib->first) {
      const double x = ia->second, y = ib->second;
      sum += std::fabs(x - y) - std::fabs(x) - std::fabs(y);
      ++ia;
      ++ib;
    } else if (ia->first < ib->first) {
      ++ia;
    } else {
      ++ib;
    }
  }
  return 0.0 - 0.5 * sum;  // +0, not -0, when nothing is in common
}

}  // namespace pvb::slam::place
