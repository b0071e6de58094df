#pragma once
// A bag-of-words vocabulary: a k-ary tree of binary descriptor centres (hierarchical k-medians
// under the Hamming distance) whose leaves are the words, each with a weight. A descriptor's word
// is found by descending from the root to the closest child at every level.
#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "place/binary_descriptor.h"
#include "place/bow_vector.h"
#include "place/feature_vector.h"

namespace edgeslam {

// How a word's occurrences in an image make its weight (before the L1 normalisation):
// tf-idf: occurrences x idf; tf: occurrences; idf: idf once; binary: 1 once.
// idf = log(training images / training images containing the word).
enum class WordWeighting : std::uint32_t { kTfIdf = 0, kTf = 1, kIdf = 2, kBinary = 3 };

std::string_view toString(WordWeighting weighting);
// Accepts "tf-idf", "tf", "idf", "binary"; throws std::invalid_argument otherwise.
WordWeighting parseWordWeighting(std::string_view text);

inline constexpr std::uint32_t kNoParent = 0xFFFFFFFFU;

// The raw tree, as training makes it and the file holds it. Node 0 is the root (parent
// kNoParent, centre unused); the other nodes are in breadth-first order: parents never decrease
// and every parent comes before its children, so each node's children are consecutive.
struct VocabularyTree {
  int branching = 0;  // k: at most this many children per node
  int levels = 0;     // L: leaves lie at depth <= L
  WordWeighting weighting = WordWeighting::kTfIdf;
  std::vector<std::uint32_t> parents;
  std::vector<Descriptor256> centres;
  std::vector<double> weights;  // per node; used for leaves (words), 0 elsewhere
  std::uint64_t training_images = 0;
  std::uint64_t training_descriptors = 0;

  friend bool operator==(const VocabularyTree&, const VocabularyTree&) = default;
};

class Vocabulary {
 public:
  Vocabulary() = default;
  // Validates and indexes `tree`; throws std::invalid_argument naming what is wrong.
  explicit Vocabulary(VocabularyTree tree);

  // Binary file (docs/vocabulary.md). Errors throw std::runtime_error naming the file and the
  // problem (missing, truncated, bad magic, unsupported version, checksum mismatch, bad tree).
  static Vocabulary load(const std::filesystem::path& path);
  void save(const std::filesystem::path& path) const;
  std::vector<std::uint8_t> serialize() const;
  // `source` names the bytes in error messages.
  static Vocabulary deserialize(std::span<const std::uint8_t> bytes,
                                const std::string& source = "<memory>");
  // FNV-1a 64 of the serialised payload (what the file's trailer holds).
  std::uint64_t checksum() const;

  bool empty() const { return tree_.parents.empty(); }
  const VocabularyTree& tree() const { return tree_; }
  int branching() const { return tree_.branching; }
  int levels() const { return tree_.levels; }
  WordWeighting weighting() const { return tree_.weighting; }
  std::size_t nodeCount() const { return tree_.parents.size(); }
  std::size_t wordCount() const { return word_nodes_.size(); }
  // Words are the leaves numbered in node order.
  NodeId wordNode(WordId word) const { return word_nodes_.at(word); }
  double wordWeight(WordId word) const { return tree_.weights[word_nodes_.at(word)]; }
  int nodeDepth(NodeId node) const { return depths_.at(node); }

  // The word of one 32-byte descriptor.
  WordId wordOf(const std::uint8_t* descriptor) const;
  // The word of every row of `descriptors` (CV_8UC1, 32 columns; may be empty).
  std::vector<WordId> words(const cv::Mat& descriptors) const;
  // The image's L1-normalised bag of words. Words whose weight is 0 (idf of a word seen in every
  // training image) are left out.
  BowVector transform(const cv::Mat& descriptors) const;
  // Also the direct index: each feature filed under its ancestor node `levels_up` levels above
  // the leaves (depth L - levels_up; the leaf itself when the leaf is shallower). levels_up = 0
  // files by word, levels_up >= L puts every feature under the root.
  void transform(const cv::Mat& descriptors, int levels_up, BowVector& bow,
                 FeatureVector& features) const;

 private:
  void checkUsable(const cv::Mat& descriptors) const;
  // Descends to the leaf; `record_depth` >= 0 also returns the node passed at that depth.
  NodeId descend(const Descriptor256& d, int record_depth, NodeId& recorded) const;
  BowVector weigh(std::vector<WordId>& words) const;

  VocabularyTree tree_;
  std::vector<std::uint32_t> first_child_;
  std::vector<std::uint32_t> child_count_;
  std::vector<std::uint8_t> depths_;
  std::vector<WordId> node_words_;  // kNoWord for inner nodes
  std::vector<NodeId> word_nodes_;
};

}  // namespace edgeslam
