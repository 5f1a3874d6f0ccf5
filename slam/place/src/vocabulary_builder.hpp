#pragma once
// Internal to pvb_slam_place: 256-bit descriptors as four 64-bit words, and
// the one friend of Vocabulary through which training and the file readers
// fill its nodes.
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "pvb/common/popcount.hpp"
#include "pvb/slam/place/vocabulary.hpp"

namespace pvb::slam::place {

/// A 256-bit descriptor; byte i of the descriptor is byte i of the array's
/// memory (copied, so that the words are aligned).
using Bits256 = std::array<std::uint64_t, 4>;

inline Bits256 pack_descriptor(const unsigned char* bytes32) {
  Bits256 b;
  std::memcpy(b.data(), bytes32, sizeof b);
  return b;
}

inline int hamming(const Bits256& a, const Bits256& b) {
  return popcount64(a[0] ^ b[0]) + popcount64(a[1] ^ b[1]) + popcount64(a[2] ^ b[2]) +
         popcount64(a[3] ^ b[3]);
}

struct VocabularyBuilder {
  using Node = Vocabulary::Node;

  /// Clears `voc` and gives it its shape and root (node 0, not a leaf).
  static void start(Vocabulary& voc, int k, int levels, std::size_t expected_nodes);
  /// Appends a node (its id is the node count before the call), registering
  /// it with its parent and, for a leaf, as the next word.  Returns what is
  /// wrong ("" when nothing): the parent is not an earlier node or is a
  /// leaf, the parent has k children already, the node is deeper than L.
  /// `depth` holds each node's depth (root 0) and grows with the nodes.
  static std::string append(Vocabulary& voc, std::vector<std::uint8_t>& depth, NodeId parent, bool leaf,
                            const unsigned char* descriptor, double weight);
  /// For a tree built by training (children linked, leaf flags not set):
  /// marks the nodes without children as leaves and numbers them as words in
  /// node order.
  static void mark_leaves_as_words(Vocabulary& voc);
  /// Lays the complete tree out for word_of (Vocabulary::branches_).
  static void lay_out(Vocabulary& voc);
  /// The first node that is not a leaf but has no children, or 0 when none.
  static NodeId first_childless_inner_node(const Vocabulary& voc);
  static std::vector<Node>& nodes(Vocabulary& voc) { return voc.nodes_; }
  static const std::vector<Node>& nodes(const Vocabulary& voc) { return voc.nodes_; }
};

}  // namespace pvb::slam::place
