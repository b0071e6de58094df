#pragma once
// The direct index of one image: for each vocabulary node at a chosen level, the indices of the
// image's features whose descriptors pass through it. Matching two images compares only features
// under the same node.
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace edgeslam {

using NodeId = std::uint32_t;

class FeatureVector {
 public:
  FeatureVector() = default;
  // From (node, feature index) pairs in any order; features keep ascending order within a node.
  static FeatureVector fromPairs(std::vector<std::pair<NodeId, int>> pairs);

  // Number of nodes (sorted ascending).
  std::size_t size() const { return nodes_.size(); }
  bool empty() const { return nodes_.empty(); }
  NodeId node(std::size_t i) const { return nodes_[i]; }
  std::span<const int> features(std::size_t i) const {
    return {features_.data() + offsets_[i], features_.data() + offsets_[i + 1]};
  }
  // Features of `node`, empty when the image has none there.
  std::span<const int> featuresOf(NodeId node) const;
  std::size_t featureCount() const { return features_.size(); }

  friend bool operator==(const FeatureVector&, const FeatureVector&) = default;

 private:
  std::vector<NodeId> nodes_;
  std::vector<std::uint32_t> offsets_{0};  // features of node i: [offsets_[i], offsets_[i + 1])
  std::vector<int> features_;
};

}  // namespace edgeslam
