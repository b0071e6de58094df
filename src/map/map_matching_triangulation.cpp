// Search for new points between two keyframes: unmatched keypoints of kf1 against the unmatched
// keypoints of kf2 that lie in the band around kf1's epipolar line. The band test (three
// multiply-adds on packed arrays) comes first so that only a few per cent of the pairs reach the
// descriptor distance.
#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <cmath>
#include <vector>

#include "features/descriptor_distance.h"
#include "features/rotation_histogram.h"
#include "map/map_matching.h"
#include "map/map_matching_internal.h"

namespace edgeslam {
namespace {

constexpr float kEpipolarChi2 = 3.84f;  // chi-square, 1 degree of freedom, 95 %
// Keypoints within this many pixels (times their scale) of the epipole triangulate badly.
constexpr float kEpipoleRadius = 10.f;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// kf2's unmatched keypoints, packed for the band test.
struct Candidates {
  std::vector<float> u, v, max_distance2;
  std::vector<int> index;
  std::vector<unsigned char> near_epipole;

  void reserve(std::size_t n) {
    u.reserve(n);
    v.reserve(n);
    max_distance2.reserve(n);
    index.reserve(n);
    near_epipole.reserve(n);
  }
};

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulation(const KeyFrame& kf1,
                                                                       const KeyFrame& kf2,
                                                                       const PinholeCamera& camera,
                                                                       bool monocular,
                                                                       float ratio) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  if (kf1.size() == 0 || kf2.size() == 0) return pairs;
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();

  // Relative pose 1 -> 2 and the fundamental matrix x2^T F21 x1 = 0.
  const Eigen::Matrix3d R1 = kf1.pose().rotationMatrix();
  const Eigen::Matrix3d R2 = kf2.pose().rotationMatrix();
  const Eigen::Matrix3d R21 = R2 * R1.transpose();
  const Eigen::Vector3d t21 = kf2.pose().translation() - R21 * kf1.pose().translation();
  if (!(t21.norm() > 1e-9)) return pairs;  // no baseline: nothing can be triangulated
  const Eigen::Matrix3d K_inv = camera.K().inverse();
  const Eigen::Matrix3d F21 = K_inv.transpose() * skew(t21) * R21 * K_inv;

  // kf1's centre seen from kf2 (t21 is that point in kf2's frame).
  const bool has_epipole = std::abs(t21.z()) > 1e-9;
  const float epipole_u =
      has_epipole ? static_cast<float>(camera.fx() * t21.x() / t21.z() + camera.cx()) : 0.f;
  const float epipole_v =
      has_epipole ? static_cast<float>(camera.fy() * t21.y() / t21.z() + camera.cy()) : 0.f;

  Candidates candidates;
  candidates.reserve(kf2.size());
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
    candidates.u.push_back(kp.pt.x);
    candidates.v.push_back(kp.pt.y);
    candidates.max_distance2.push_back(kEpipolarChi2 *
                                       static_cast<float>(f2.scales.sigma2(kp.octave)));
    candidates.index.push_back(static_cast<int>(j));
    candidates.near_epipole.push_back(near_matters ? 1 : 0);
  }
  const std::size_t m = candidates.index.size();
  if (m == 0) return pairs;

  // One match per kf2 keypoint: the closest kf1 keypoint wins.
  std::vector<int> owner(kf2.size(), -1);
  std::vector<int> owner_distance(kf2.size(), INT_MAX);
  const float* cu = candidates.u.data();
  const float* cv_ = candidates.v.data();
  const float* cmax = candidates.max_distance2.data();
  for (std::size_t i = 0; i < kf1.size(); ++i) {
    if (matching_detail::isUsable(kf1.point(i))) continue;
    const cv::KeyPoint& kp1 = f1.keypoints[i];
    const Eigen::Vector3d line = F21 * Eigen::Vector3d(kp1.pt.x, kp1.pt.y, 1.0);
    const double norm = std::hypot(line.x(), line.y());
    if (!(norm > 0.0)) continue;
    // Normalised line: a*u + b*v + c is the signed pixel distance.
    const float a = static_cast<float>(line.x() / norm);
    const float b = static_cast<float>(line.y() / norm);
    const float c = static_cast<float>(line.z() / norm);
    const bool depth1 = f1.hasDepth(i);
    const std::uint8_t* descriptor = f1.descriptors.ptr<std::uint8_t>(static_cast<int>(i));

    int best_distance = INT_MAX, second_distance = INT_MAX, best_k = -1;
    for (std::size_t k = 0; k < m; ++k) {
      const float d = a * cu[k] + b * cv_[k] + c;
      if (d * d >= cmax[k]) continue;
      if (candidates.near_epipole[k] && !depth1) continue;
      const int distance =
          descriptorDistance(descriptor, f2.descriptors.ptr<std::uint8_t>(candidates.index[k]));
      if (distance < best_distance) {
        second_distance = best_distance;
        best_distance = distance;
        best_k = static_cast<int>(k);
      } else if (distance < second_distance) {
        second_distance = distance;
      }
    }
    if (best_k < 0 || best_distance > kMatchDistanceLow) continue;
    if (second_distance != INT_MAX &&
        static_cast<float>(best_distance) >= ratio * static_cast<float>(second_distance)) {
      continue;
    }
    const auto j = static_cast<std::size_t>(candidates.index[static_cast<std::size_t>(best_k)]);
    if (best_distance < owner_distance[j]) {
      owner[j] = static_cast<int>(i);
      owner_distance[j] = best_distance;
    }
  }

  RotationHistogram histogram;
  for (std::size_t j = 0; j < kf2.size(); ++j) {
    if (owner[j] >= 0) {
      histogram.add(f1.keypoints[static_cast<std::size_t>(owner[j])].angle, f2.keypoints[j].angle,
                    static_cast<int>(j));
    }
  }
  for (const int j : histogram.consistent()) {
    pairs.emplace_back(static_cast<std::size_t>(owner[static_cast<std::size_t>(j)]),
                       static_cast<std::size_t>(j));
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace edgeslam
