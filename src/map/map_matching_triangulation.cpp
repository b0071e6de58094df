// Search for new points between two keyframes: unmatched keypoints of kf1 against the unmatched
// keypoints of kf2 that lie in the band around kf1's epipolar line. The band test (three
// multiply-adds on packed arrays) comes first so that only a few per cent of the pairs reach the
// descriptor distance. Also the geometry and bookkeeping shared with the bag-of-words variant.
#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <cmath>
#include <vector>

#include "features/descriptor_distance.h"
#include "features/rotation_histogram.h"
#include "map/map_matching.h"
#include "map/map_matching_internal.h"
#include "map/map_matching_triangulation_internal.h"

namespace edgeslam {
namespace triangulation_detail {
namespace {

constexpr float kEpipolarChi2 = 3.84f;  // chi-square, 1 degree of freedom, 95 %
// Keypoints within this many pixels (times their scale) of the epipole triangulate badly.
constexpr float kEpipoleRadius = 10.f;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace

TriangulationGeometry::TriangulationGeometry(const KeyFrame& kf1, const KeyFrame& kf2,
                                             const PinholeCamera& camera, bool monocular) {
  // Relative pose 1 -> 2 and the fundamental matrix x2^T F21 x1 = 0.
  const Eigen::Matrix3d R1 = kf1.pose().rotationMatrix();
  const Eigen::Matrix3d R2 = kf2.pose().rotationMatrix();
  const Eigen::Matrix3d R21 = R2 * R1.transpose();
  const Eigen::Vector3d t21 = kf2.pose().translation() - R21 * kf1.pose().translation();
  has_baseline_ = t21.norm() > 1e-9;
  if (!has_baseline_) return;
  const Eigen::Matrix3d K_inv = camera.K().inverse();
  F21_ = K_inv.transpose() * skew(t21) * R21 * K_inv;

  // kf1's centre seen from kf2 (t21 is that point in kf2's frame).
  const bool has_epipole = std::abs(t21.z()) > 1e-9;
  const float epipole_u =
      has_epipole ? static_cast<float>(camera.fx() * t21.x() / t21.z() + camera.cx()) : 0.f;
  const float epipole_v =
      has_epipole ? static_cast<float>(camera.fy() * t21.y() / t21.z() + camera.cy()) : 0.f;

  const FrameFeatures& f2 = kf2.features();
  candidacy_.assign(kf2.size(), Candidacy::kNone);
  max_distance2_.assign(kf2.size(), 0.f);
  for (std::size_t j = 0; j < kf2.size(); ++j) {
    if (matching_detail::isUsable(kf2.point(j))) continue;
    const cv::KeyPoint& kp = f2.keypoints[j];
    const float scale = static_cast<float>(f2.scales.scale(kp.octave));
    const float du = kp.pt.x - epipole_u, dv = kp.pt.y - epipole_v;
    const bool near =
        has_epipole && du * du + dv * dv < kEpipoleRadius * kEpipoleRadius * scale * scale;
    // Depth from the sensor makes a point near the epipole well defined after all.
    const bool near_matters = near && (monocular || !f2.hasDepth(j));
    if (monocular && near_matters) continue;
    candidacy_[j] = near_matters ? Candidacy::kNeedsDepthInKf1 : Candidacy::kAny;
    max_distance2_[j] = kEpipolarChi2 * static_cast<float>(f2.scales.sigma2(kp.octave));
  }
}

std::optional<EpipolarLine> TriangulationGeometry::lineOf(const cv::KeyPoint& kp1) const {
  const Eigen::Vector3d line = F21_ * Eigen::Vector3d(kp1.pt.x, kp1.pt.y, 1.0);
  const double norm = std::hypot(line.x(), line.y());
  if (!(norm > 0.0)) return std::nullopt;
  return EpipolarLine{static_cast<float>(line.x() / norm), static_cast<float>(line.y() / norm),
                      static_cast<float>(line.z() / norm)};
}

bool passesDistanceAndRatio(const matching_detail::BestTwoWithLevels& best, float ratio) {
  if (best.index < 0 || best.distance > kMatchDistanceLow) return false;
  return best.second_distance == INT_MAX ||
         static_cast<float>(best.distance) < ratio * static_cast<float>(best.second_distance);
}

Pairs OnePairPerKf2Keypoint::rotationConsistentPairs(const KeyFrame& kf1,
                                                     const KeyFrame& kf2) const {
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();
  RotationHistogram histogram;
  for (std::size_t j = 0; j < owner_.size(); ++j) {
    if (owner_[j] >= 0) {
      histogram.add(f1.keypoints[static_cast<std::size_t>(owner_[j])].angle, f2.keypoints[j].angle,
                    static_cast<int>(j));
    }
  }
  Pairs pairs;
  for (const int j : histogram.consistent()) {
    pairs.emplace_back(static_cast<std::size_t>(owner_[static_cast<std::size_t>(j)]),
                       static_cast<std::size_t>(j));
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace triangulation_detail

std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulation(const KeyFrame& kf1,
                                                                       const KeyFrame& kf2,
                                                                       const PinholeCamera& camera,
                                                                       bool monocular,
                                                                       float ratio) {
  using namespace triangulation_detail;
  if (kf1.size() == 0 || kf2.size() == 0) return {};
  const TriangulationGeometry geometry(kf1, kf2, camera, monocular);
  if (!geometry.hasBaseline()) return {};
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();

  // kf2's candidate keypoints, packed for the band test.
  std::vector<float> cu, cv_, cmax;
  std::vector<int> index;
  std::vector<unsigned char> needs_depth;
  for (std::size_t j = 0; j < kf2.size(); ++j) {
    const Candidacy c = geometry.candidacy()[j];
    if (c == Candidacy::kNone) continue;
    cu.push_back(f2.keypoints[j].pt.x);
    cv_.push_back(f2.keypoints[j].pt.y);
    cmax.push_back(geometry.maxDistance2()[j]);
    index.push_back(static_cast<int>(j));
    needs_depth.push_back(c == Candidacy::kNeedsDepthInKf1 ? 1 : 0);
  }
  const std::size_t m = index.size();
  if (m == 0) return {};

  OnePairPerKf2Keypoint owners(kf2.size());
  for (std::size_t i = 0; i < kf1.size(); ++i) {
    if (matching_detail::isUsable(kf1.point(i))) continue;
    const std::optional<EpipolarLine> line = geometry.lineOf(f1.keypoints[i]);
    if (!line) continue;
    const float a = line->a, b = line->b, c = line->c;
    const bool depth1 = f1.hasDepth(i);
    const std::uint8_t* descriptor = f1.descriptors.ptr<std::uint8_t>(static_cast<int>(i));

    matching_detail::BestTwoWithLevels best;
    for (std::size_t k = 0; k < m; ++k) {
      const float d = a * cu[k] + b * cv_[k] + c;
      if (d * d >= cmax[k]) continue;
      if (needs_depth[k] && !depth1) continue;
      best.consider(static_cast<int>(k),
                    descriptorDistance(descriptor, f2.descriptors.ptr<std::uint8_t>(index[k])), 0);
    }
    if (!passesDistanceAndRatio(best, ratio)) continue;
    owners.propose(i, static_cast<std::size_t>(index[static_cast<std::size_t>(best.index)]),
                   best.distance);
  }
  return owners.rotationConsistentPairs(kf1, kf2);
}

}  // namespace edgeslam
