#include "place/feature_vector.h"

#include <algorithm>

namespace edgeslam {

FeatureVector FeatureVector::fromPairs(std::vector<std::pair<NodeId, int>> pairs) {
  // Decoded ones come in order already (a stored map's 1000 direct indices).
  if (!std::is_sorted(pairs.begin(), pairs.end())) std::sort(pairs.begin(), pairs.end());
  FeatureVector fv;
  fv.features_.reserve(pairs.size());
  for (const auto& [node, feature] : pairs) {
    if (fv.nodes_.empty() || fv.nodes_.back() != node) {
      if (!fv.nodes_.empty())
        fv.offsets_.push_back(static_cast<std::uint32_t>(fv.features_.size()));
      fv.nodes_.push_back(node);
    }
    fv.features_.push_back(feature);
  }
  if (!fv.nodes_.empty()) fv.offsets_.push_back(static_cast<std::uint32_t>(fv.features_.size()));
  return fv;
}

std::span<const int> FeatureVector::featuresOf(NodeId node) const {
  const auto it = std::lower_bound(nodes_.begin(), nodes_.end(), node);
  if (it == nodes_.end() || *it != node) return {};
  return features(static_cast<std::size_t>(it - nodes_.begin()));
}

}  // namespace edgeslam
