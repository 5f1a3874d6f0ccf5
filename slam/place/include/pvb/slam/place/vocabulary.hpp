#pragma once
// A bag-of-binary-words vocabulary for 256-bit ORB descriptors (Galvez-Lopez
// & Tardos 2012, DBoW2; the design ORB-SLAM2 uses): a tree of k branches and
// L levels built by hierarchical k-means++ with binary k-medians centres,
// TF-IDF word weights and the L1 score.
//
// Node 0 is the root and a node's children have consecutive ids.  train()
// numbers breadth-first (the root's children, then their children in
// order); DBoW2's own training numbers a node's children when it splits the
// node, depth first.  load() keeps a file's numbering, whichever it is (a
// parent always comes before its children).  Words are the leaves,
// numbered 0..size()-1 in node order.  A leaf is at depth L or above (a
// node with at most one training descriptor is not split).
//
// The direct index: transform(..., levels_up) groups features by the node
// at depth L - levels_up on their path from the root, as DBoW2 does
// (ORB-SLAM2 uses 4 with L = 6); the root when L - levels_up <= 0, and the
// leaf itself when the path ends above that depth.
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace pvb::slam::place {

using WordId = std::uint32_t;
using NodeId = std::uint32_t;

/// A normalised bag of words: (word, weight) in ascending words, each word
/// once, the weights summing to 1 (L1).  A sorted array rather than a
/// std::map: an image has about as many words as features, and a map node
/// per word costs 64 bytes where the pair costs 16.
using BowVector = std::vector<std::pair<WordId, double>>;
/// The direct index of one image: (node, indices of its features (rows of
/// the descriptor matrix), ascending) in ascending nodes.
using FeatureVector = std::vector<std::pair<NodeId, std::vector<std::uint32_t>>>;

struct TrainParams {
  int k = 10;               ///< branching factor, in [2, 64]
  int levels = 6;           ///< depth L, in [1, 8]
  std::uint64_t seed = 1;   ///< k-means++ seeding; equal inputs and seed give equal vocabularies
  int max_iterations = 10;  ///< k-medians iterations per node (stops earlier when stable)
};

/// What train() did, for `pvbench vocab`.
struct TrainReport {
  std::size_t images = 0, descriptors = 0, nodes = 0, words = 0;
  double seconds = 0;
};

class Vocabulary {
 public:
  Vocabulary() = default;

  /// Trains from the descriptors of each image (CV_8U, N x 32 each; empty
  /// images are skipped).  The IDF weight of a word is ln(N / N_i), N the
  /// non-empty images (DBoW2 counts empty ones too) and N_i the images with
  /// at least one descriptor in the word.
  /// Throws pvb::ConfigError on bad params, no descriptors or a wrong type.
  /// As DBoW2: a node with at most k descriptors gets one child per
  /// descriptor; centres are binary medians (a bit is set when at least
  /// half of the members have it); N_i counts the images whose descriptors
  /// transform() puts in the word.  Unlike DBoW2, k-means++ draws with
  /// probability proportional to the squared Hamming distance (DBoW2 uses
  /// the distance), a centre left without members makes no child, and the
  /// k-medians loop stops after params.max_iterations.
  static Vocabulary train(const std::vector<cv::Mat>& descriptors_per_image, const TrainParams& params,
                          TrainReport* report = nullptr);

  /// Reads either format, told apart by the first bytes: our binary format
  /// or DBoW2's text format (ORB-SLAM2's ORBvoc.txt).  A missing, bad or
  /// truncated file throws pvb::IoError naming the file and the line (text)
  /// or byte offset (binary).
  static Vocabulary load(const std::string& path);
  /// load(), once per process for as long as the file keeps its size and
  /// modification time: the systems of one process (a comparison, the
  /// sessions of a campaign) share the last vocabulary read.  Thread-safe.
  static std::shared_ptr<const Vocabulary> load_shared(const std::string& path);
  /// Our binary format (docs/place_recognition.md).  Written through a
  /// temporary file: a failed write keeps the old file.
  void save_binary(const std::string& path) const;
  /// DBoW2's text format: "k L scoring weighting", then one line per node
  /// after the root: "parent is_leaf d0 ... d31 weight".
  void save_text(const std::string& path) const;

  bool empty() const { return words_.empty(); }
  int k() const { return k_; }
  int levels() const { return levels_; }
  std::size_t size() const { return words_.size(); }        ///< words
  std::size_t node_count() const { return nodes_.size(); }  ///< including the root
  /// FNV-1a of what decides words and weights (k, L, every node's parent,
  /// leaf flag, centre and weight): the same for a vocabulary and its copy
  /// in the other file format, different for any other vocabulary.  Maps
  /// record it, so that a map is never searched with another vocabulary.
  std::uint64_t fingerprint() const;

  /// Bag of words of an image's descriptors (CV_8U, N x 32), L1-normalised
  /// TF-IDF, and its direct index at `levels_up` above the leaves (fv may be null).
  /// A descriptor whose word weighs 0 (in every training image) is in
  /// neither, as in DBoW2.  Throws pvb::ConfigError on a wrong type.
  void transform(const cv::Mat& descriptors, BowVector* bow, FeatureVector* fv = nullptr,
                 int levels_up = 4) const;
  /// The word of one descriptor (32 bytes), and its weight: down from the
  /// root to the nearest child (Hamming; ties to the first) until a leaf.
  /// `node_at_level`: the node at depth L - levels_up on the way (see
  /// above).  The vocabulary must not be empty (std::logic_error).
  WordId word_of(const unsigned char* descriptor, double* weight = nullptr, NodeId* node_at_level = nullptr,
                 int levels_up = 0) const;
  /// DBoW2's L1 score of two normalised vectors: 1 - 0.5 * |a - b|_1, in [0, 1].
  static double score(const BowVector& a, const BowVector& b);

  /// Access for tests and tools.
  const std::vector<NodeId>& children(NodeId n) const { return nodes_.at(n).children; }
  const unsigned char* centre(NodeId n) const { return nodes_.at(n).descriptor.data(); }
  double word_weight(WordId w) const { return nodes_.at(words_.at(w)).weight; }
  NodeId word_node(WordId w) const { return words_.at(w); }

 private:
  struct Node {
    NodeId parent = 0;
    std::vector<NodeId> children;
    std::array<unsigned char, 32> descriptor{};
    double weight = 0;  ///< IDF, leaves only
    WordId word = 0;    ///< leaves only
    bool leaf = false;
  };
  friend struct VocabularyBuilder;  ///< training and file formats (src/vocabulary_builder.hpp)

  int k_ = 0, levels_ = 0;
  std::vector<Node> nodes_;
  std::vector<NodeId> words_;  ///< word -> node
  /// One child in the tree's layout for descending: the children of a node
  /// side by side, each with where its own children are, so that a step
  /// down reads one run of memory (built by VocabularyBuilder::lay_out).
  struct Branch {
    std::array<std::uint64_t, 4> bits{};  ///< the child's descriptor
    std::uint32_t first = 0, last = 0;    ///< its children: branches_[first, last) (none for a leaf)
    NodeId node = 0;                      ///< the child
  };
  std::vector<Branch> branches_;  ///< the root's children first, at [0, root_children_)
  std::uint32_t root_children_ = 0;
};

}  // namespace pvb::slam::place
