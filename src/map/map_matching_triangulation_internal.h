#pragma once
// What the two new-point searches (epipolar band and bag of words) share, not part of the public
// API: the epipolar geometry of a keyframe pair with the checks every candidate pair must pass,
// and the one-pair-per-kf2-keypoint bookkeeping followed by the rotation-consistency filter.
#include <Eigen/Core>
#include <climits>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "geometry/camera.h"
#include "map/keyframe.h"
#include "map/map_matching_internal.h"

namespace edgeslam::triangulation_detail {

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

// A kf1 keypoint's epipolar line in kf2, scaled so that a*u + b*v + c is the signed distance in
// pixels.
struct EpipolarLine {
  float a = 0.f, b = 0.f, c = 0.f;
  float distance(float u, float v) const { return a * u + b * v + c; }
};

// How a kf2 keypoint may take part: not at all (it has a point, or it lies near the epipole of a
// monocular pair), freely, or only with a kf1 keypoint that has sensor depth (near the epipole
// itself without depth).
enum class Candidacy : unsigned char { kNone, kAny, kNeedsDepthInKf1 };

class TriangulationGeometry {
 public:
  TriangulationGeometry(const KeyFrame& kf1, const KeyFrame& kf2, const PinholeCamera& camera,
                        bool monocular);

  // False for (almost) no baseline: nothing can be triangulated.
  bool hasBaseline() const { return has_baseline_; }
  // nullopt for a degenerate line.
  std::optional<EpipolarLine> lineOf(const cv::KeyPoint& kp1) const;
  // Per kf2 keypoint, with the squared band half-width 3.84 * sigma^2 of its level.
  const std::vector<Candidacy>& candidacy() const { return candidacy_; }
  const std::vector<float>& maxDistance2() const { return max_distance2_; }

  // The epipolar and epipole checks of the pair (kf1 keypoint with `line` / `kf1_has_depth`, kf2
  // keypoint j).
  bool accepts(const EpipolarLine& line, bool kf1_has_depth, std::size_t j,
               const cv::KeyPoint& kp2) const {
    const Candidacy c = candidacy_[j];
    if (c == Candidacy::kNone || (c == Candidacy::kNeedsDepthInKf1 && !kf1_has_depth)) {
      return false;
    }
    const float d = line.distance(kp2.pt.x, kp2.pt.y);
    return d * d < max_distance2_[j];
  }

 private:
  Eigen::Matrix3d F21_;
  bool has_baseline_ = false;
  std::vector<Candidacy> candidacy_;
  std::vector<float> max_distance2_;
};

// Whether the closest candidate is close enough (Hamming <= kMatchDistanceLow) and clearly closer
// than the second (best < ratio * second, when there is a second).
bool passesDistanceAndRatio(const matching_detail::BestTwoWithLevels& best, float ratio);

// At most one kf1 keypoint per kf2 keypoint: the closest descriptor wins (the first proposed on a
// tie).
class OnePairPerKf2Keypoint {
 public:
  explicit OnePairPerKf2Keypoint(std::size_t kf2_size)
      : owner_(kf2_size, -1), owner_distance_(kf2_size, INT_MAX) {}

  void propose(std::size_t i, std::size_t j, int distance) {
    if (distance < owner_distance_[j]) {
      owner_[j] = static_cast<int>(i);
      owner_distance_[j] = distance;
    }
  }

  // The pairs whose change of keypoint angle is in the dominant rotation bins, sorted.
  Pairs rotationConsistentPairs(const KeyFrame& kf1, const KeyFrame& kf2) const;

 private:
  std::vector<int> owner_;
  std::vector<int> owner_distance_;
};

}  // namespace edgeslam::triangulation_detail
