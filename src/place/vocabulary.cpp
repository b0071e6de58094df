#include "place/vocabulary.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

constexpr WordId kNoWord = 0xFFFFFFFFU;
constexpr int kMaxBranching = 256;
constexpr int kMaxLevels = 16;

}  // namespace

std::string_view toString(WordWeighting weighting) {
  switch (weighting) {
    case WordWeighting::kTfIdf:
      return "tf-idf";
    case WordWeighting::kTf:
      return "tf";
    case WordWeighting::kIdf:
      return "idf";
    case WordWeighting::kBinary:
      return "binary";
  }
  return "unknown";
}

WordWeighting parseWordWeighting(std::string_view text) {
  for (const WordWeighting w :
       {WordWeighting::kTfIdf, WordWeighting::kTf, WordWeighting::kIdf, WordWeighting::kBinary}) {
    if (text == toString(w)) return w;
  }
  throw std::invalid_argument(
      fmt::format("unknown word weighting '{}' (expected tf-idf, tf, idf or binary)", text));
}

Vocabulary::Vocabulary(VocabularyTree tree) : tree_(std::move(tree)) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("invalid vocabulary tree: " + what);
  };
  if (tree_.branching < 2 || tree_.branching > kMaxBranching) {
    fail(fmt::format("branching {} outside [2, {}]", tree_.branching, kMaxBranching));
  }
  if (tree_.levels < 1 || tree_.levels > kMaxLevels) {
    fail(fmt::format("levels {} outside [1, {}]", tree_.levels, kMaxLevels));
  }
  if (static_cast<std::uint32_t>(tree_.weighting) >
      static_cast<std::uint32_t>(WordWeighting::kBinary)) {
    fail(fmt::format("unknown weighting code {}", static_cast<std::uint32_t>(tree_.weighting)));
  }
  const std::size_t n = tree_.parents.size();
  if (n < 2) fail(fmt::format("{} nodes (a root and at least one word are needed)", n));
  if (n >= kNoParent) fail(fmt::format("{} nodes is too many", n));
  if (tree_.centres.size() != n || tree_.weights.size() != n) {
    fail(fmt::format("{} parents but {} centres and {} weights", n, tree_.centres.size(),
                     tree_.weights.size()));
  }
  if (tree_.parents[0] != kNoParent) fail("node 0 is not the root");

  first_child_.assign(n, 0);
  child_count_.assign(n, 0);
  depths_.assign(n, 0);
  for (std::size_t i = 1; i < n; ++i) {
    const std::uint32_t parent = tree_.parents[i];
    if (parent >= i)
      fail(fmt::format("node {} has parent {} (parents must come first)", i, parent));
    if (i > 1 && parent < tree_.parents[i - 1]) {
      fail(fmt::format("node {} breaks the breadth-first order (parent {} after {})", i, parent,
                       tree_.parents[i - 1]));
    }
    if (child_count_[parent] == 0) first_child_[parent] = static_cast<std::uint32_t>(i);
    if (++child_count_[parent] > static_cast<std::uint32_t>(tree_.branching)) {
      fail(fmt::format("node {} has more than {} children", parent, tree_.branching));
    }
    depths_[i] = static_cast<std::uint8_t>(depths_[parent] + 1);
    if (depths_[i] > tree_.levels) {
      fail(fmt::format("node {} lies at depth {} > levels {}", i, depths_[i], tree_.levels));
    }
  }
  node_words_.assign(n, kNoWord);
  for (std::size_t i = 1; i < n; ++i) {
    if (!std::isfinite(tree_.weights[i]) || tree_.weights[i] < 0.0) {
      fail(fmt::format("node {} has weight {}", i, tree_.weights[i]));
    }
    if (child_count_[i] == 0) {
      node_words_[i] = static_cast<WordId>(word_nodes_.size());
      word_nodes_.push_back(static_cast<NodeId>(i));
    }
  }
}

void Vocabulary::checkUsable(const cv::Mat& descriptors) const {
  if (empty()) throw std::logic_error("the vocabulary is empty (train or load one first)");
  if (descriptors.empty()) return;
  if (descriptors.type() != CV_8UC1 || descriptors.cols != kDescriptorBytes) {
    throw std::invalid_argument(
        fmt::format("descriptors must be CV_8UC1 with {} columns, got type {} with {} columns",
                    kDescriptorBytes, descriptors.type(), descriptors.cols));
  }
}

NodeId Vocabulary::descend(const Descriptor256& d, int record_depth, NodeId& recorded) const {
  NodeId node = 0;
  recorded = 0;
  int depth = 0;
  while (child_count_[node] != 0) {
    const std::uint32_t first = first_child_[node];
    const std::uint32_t end = first + child_count_[node];
    NodeId best = first;
    int best_distance = hammingDistance(d, tree_.centres[first]);
    for (std::uint32_t c = first + 1; c < end; ++c) {
      const int distance = hammingDistance(d, tree_.centres[c]);
      if (distance < best_distance) {
        best_distance = distance;
        best = c;
      }
    }
    node = best;
    if (++depth <= record_depth) recorded = node;
  }
  return node;
}

WordId Vocabulary::wordOf(const std::uint8_t* descriptor) const {
  if (empty()) throw std::logic_error("the vocabulary is empty (train or load one first)");
  NodeId unused = 0;
  return node_words_[descend(Descriptor256::fromBytes(descriptor), -1, unused)];
}

std::vector<WordId> Vocabulary::words(const cv::Mat& descriptors) const {
  checkUsable(descriptors);
  std::vector<WordId> result(static_cast<std::size_t>(descriptors.rows));
  NodeId unused = 0;
  for (int r = 0; r < descriptors.rows; ++r) {
    result[r] = node_words_[descend(Descriptor256::fromBytes(descriptors.ptr<std::uint8_t>(r)), -1,
                                    unused)];
  }
  return result;
}

BowVector Vocabulary::weigh(std::vector<WordId>& words) const {
  std::sort(words.begin(), words.end());
  const bool counts_occurrences =
      tree_.weighting == WordWeighting::kTfIdf || tree_.weighting == WordWeighting::kTf;
  const bool uses_idf =
      tree_.weighting == WordWeighting::kTfIdf || tree_.weighting == WordWeighting::kIdf;
  BowVector bow;
  for (std::size_t i = 0; i < words.size();) {
    std::size_t j = i;
    while (j < words.size() && words[j] == words[i]) ++j;
    const double base = uses_idf ? tree_.weights[word_nodes_[words[i]]] : 1.0;
    const double weight = counts_occurrences ? base * static_cast<double>(j - i) : base;
    if (weight > 0.0) bow.entries.push_back({words[i], weight});
    i = j;
  }
  normalizeL1(bow);
  return bow;
}

BowVector Vocabulary::transform(const cv::Mat& descriptors) const {
  std::vector<WordId> ids = words(descriptors);
  return weigh(ids);
}

void Vocabulary::transform(const cv::Mat& descriptors, int levels_up, BowVector& bow,
                           FeatureVector& features) const {
  checkUsable(descriptors);
  const int record_depth = std::max(0, tree_.levels - std::max(0, levels_up));
  std::vector<WordId> ids(static_cast<std::size_t>(descriptors.rows));
  std::vector<std::pair<NodeId, int>> pairs(ids.size());
  for (int r = 0; r < descriptors.rows; ++r) {
    NodeId recorded = 0;
    const NodeId leaf =
        descend(Descriptor256::fromBytes(descriptors.ptr<std::uint8_t>(r)), record_depth, recorded);
    ids[r] = node_words_[leaf];
    pairs[r] = {recorded, r};
  }
  bow = weigh(ids);
  features = FeatureVector::fromPairs(std::move(pairs));
}

}  // namespace edgeslam
