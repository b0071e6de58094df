// Bag-of-words search for new points between two keyframes: only keypoints filed under the same
// node of the two direct indexes are compared (a few per node instead of the whole band), then
// the checks of the band search.
#include <fmt/format.h>

#include <optional>
#include <stdexcept>
#include <vector>

#include "features/descriptor_distance.h"
#include "map/map_matching.h"
#include "map/map_matching_internal.h"
#include "map/map_matching_triangulation_internal.h"

namespace edgeslam {
namespace {

[[noreturn]] void throwIndexOutOfRange(const KeyFrame& keyframe, int feature) {
  throw std::invalid_argument(fmt::format(
      "matchForTriangulationByBow: keyframe {} files feature {} in its direct index but has {} "
      "keypoints (described from other features?)",
      keyframe.id(), feature, keyframe.size()));
}

}  // namespace

bool canMatchForTriangulationByBow(const KeyFrame& kf1, const KeyFrame& kf2) {
  const auto place1 = kf1.place();
  const auto place2 = kf2.place();
  return place1 != nullptr && place2 != nullptr &&
         place1->direct_index_depth == place2->direct_index_depth &&
         place1->vocabulary == place2->vocabulary;
}

std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulationByBow(
    const KeyFrame& kf1, const KeyFrame& kf2, const PinholeCamera& camera, bool monocular,
    float ratio) {
  using namespace triangulation_detail;
  if (!canMatchForTriangulationByBow(kf1, kf2)) {
    return matchForTriangulation(kf1, kf2, camera, monocular, ratio);
  }
  if (kf1.size() == 0 || kf2.size() == 0) return {};
  const TriangulationGeometry geometry(kf1, kf2, camera, monocular);
  if (!geometry.hasBaseline()) return {};
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();
  const auto place1 = kf1.place();
  const auto place2 = kf2.place();
  const FeatureVector& index1 = place1->features;
  const FeatureVector& index2 = place2->features;

  OnePairPerKf2Keypoint owners(kf2.size());
  std::size_t n1 = 0, n2 = 0;
  while (n1 < index1.size() && n2 < index2.size()) {
    if (index1.node(n1) < index2.node(n2)) {
      ++n1;
      continue;
    }
    if (index2.node(n2) < index1.node(n1)) {
      ++n2;
      continue;
    }
    const auto candidates = index2.features(n2);
    for (const int feature1 : index1.features(n1)) {
      const auto i = static_cast<std::size_t>(feature1);
      if (i >= kf1.size()) throwIndexOutOfRange(kf1, feature1);
      if (matching_detail::isUsable(kf1.point(i))) continue;
      const std::optional<EpipolarLine> line = geometry.lineOf(f1.keypoints[i]);
      if (!line) continue;
      const bool depth1 = f1.hasDepth(i);
      const std::uint8_t* descriptor = f1.descriptors.ptr<std::uint8_t>(feature1);

      matching_detail::BestTwoWithLevels best;
      for (const int feature2 : candidates) {
        const auto j = static_cast<std::size_t>(feature2);
        if (j >= kf2.size()) throwIndexOutOfRange(kf2, feature2);
        if (!geometry.accepts(*line, depth1, j, f2.keypoints[j])) continue;
        best.consider(feature2,
                      descriptorDistance(descriptor, f2.descriptors.ptr<std::uint8_t>(feature2)),
                      0);
      }
      if (!passesDistanceAndRatio(best, ratio)) continue;
      owners.propose(i, static_cast<std::size_t>(best.index), best.distance);
    }
    ++n1;
    ++n2;
  }
  return owners.rotationConsistentPairs(kf1, kf2);
}

}  // namespace edgeslam
