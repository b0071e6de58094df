#pragma once
// Field-by-field comparison of wire records after a round trip: exact for ids, integers, bytes and
// the values that travel unquantised; within the documented quantisation steps for the others
// (keypoint coordinates 1/32 px, angles 1/65536 turn, depths 1 mm, float32 positions and slice
// poses, int16 normals).
#include <gtest/gtest.h>

#include <cmath>

#include "map/map_records.h"

namespace edgeslam::test {

// Largest round-trip errors the wire may introduce (plus float rounding of the decoded value).
constexpr double kCoordinateTolerancePx = 1.0 / 64.0 + 1e-4;
constexpr double kAngleToleranceDeg = 360.0 / 256.0 / 2.0 + 1e-4;  // one byte per angle
constexpr double kDepthToleranceM = 0.0005 + 1e-6;
constexpr double kNormalTolerance = 1.0 / 32767.0;
constexpr double kFloat32Relative = 1e-7;

inline void expectPoseNear(const SE3d& a, const SE3d& b, double tolerance = 1e-12) {
  EXPECT_LT((a.rotation().coeffs() - b.rotation().coeffs()).norm(), tolerance);
  EXPECT_LT((a.translation() - b.translation()).norm(),
            tolerance * std::max(1.0, a.translation().norm()));
}

inline double angleDifferenceDeg(float a, float b) {
  const double d = std::fmod(std::abs(static_cast<double>(a) - b), 360.0);
  return std::min(d, 360.0 - d);
}

// `b` is `a` after a round trip. Depth, when present, is within a millimetre step (unknown
// depths decode as -1 from millimetres); right_u is exact when sent, or rebuilt from the decoded
// values.
inline void expectKeyFrameNear(const KeyFrameRecord& a, const KeyFrameRecord& b,
                               bool compare_response = true) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.frame_index, b.frame_index);
  EXPECT_EQ(a.timestamp, b.timestamp);
  expectPoseNear(a.T_cw, b.T_cw);
  EXPECT_EQ(a.parent, b.parent);
  const KeyFrameFeaturesRecord& fa = a.features;
  const KeyFrameFeaturesRecord& fb = b.features;
  ASSERT_EQ(fa.keypoints.size(), fb.keypoints.size());
  for (std::size_t i = 0; i < fa.keypoints.size(); ++i) {
    const cv::KeyPoint& ka = fa.keypoints[i];
    const cv::KeyPoint& kb = fb.keypoints[i];
    EXPECT_LE(std::abs(ka.pt.x - kb.pt.x), kCoordinateTolerancePx) << i;
    EXPECT_LE(std::abs(ka.pt.y - kb.pt.y), kCoordinateTolerancePx) << i;
    EXPECT_LE(angleDifferenceDeg(ka.angle, kb.angle), kAngleToleranceDeg) << i;
    EXPECT_GE(kb.angle, 0.f);
    EXPECT_LT(kb.angle, 360.f);
    EXPECT_EQ(ka.octave, kb.octave) << i;
    EXPECT_EQ(ka.size, kb.size) << i;
    if (compare_response) {
      EXPECT_EQ(ka.response, kb.response) << i;
    }
  }
  ASSERT_EQ(fa.descriptors.rows, fb.descriptors.rows);
  if (!fa.descriptors.empty()) {
    EXPECT_EQ(cv::norm(fa.descriptors, fb.descriptors, cv::NORM_HAMMING), 0.0);
  }
  ASSERT_EQ(fa.depth.size(), fb.depth.size());
  for (std::size_t i = 0; i < fa.depth.size(); ++i) {
    if (fa.depth[i] > 0.f) {
      EXPECT_LE(std::abs(fa.depth[i] - fb.depth[i]), kDepthToleranceM) << i;
    } else {  // unknown: -1 from millimetres, as it was from floats
      EXPECT_TRUE(fb.depth[i] == -1.f || fb.depth[i] == fa.depth[i]) << i << ": " << fb.depth[i];
    }
  }
  ASSERT_EQ(fa.right_u.size(), fb.right_u.size());
  for (std::size_t i = 0; i < fa.right_u.size(); ++i) {
    if (fa.right_u[i] == fb.right_u[i]) continue;  // sent, or rebuilt to the same float
    // Rebuilt from the decoded depth: the error follows from the coordinate and depth steps.
    ASSERT_GT(fb.depth[i], 0.f) << i;
    EXPECT_EQ(fb.right_u[i], fb.keypoints[i].pt.x - fb.bf / fb.depth[i]) << i;
    const double d = fb.depth[i];
    const double bound = kCoordinateTolerancePx + fb.bf * kDepthToleranceM / (d * (d - 0.0005));
    EXPECT_LE(std::abs(fa.right_u[i] - fb.right_u[i]), bound) << i;
  }
  EXPECT_EQ(fa.pyramid_levels, fb.pyramid_levels);
  EXPECT_EQ(fa.scale_factor, fb.scale_factor);
  EXPECT_EQ(fa.bf, fb.bf);
  EXPECT_EQ(a.point_ids, b.point_ids);
}

inline void expectPositionNear(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  EXPECT_LE((a - b).norm(), kFloat32Relative * std::max(1.0, a.norm()));
}

// Without appearance, `b` has zero normal, descriptor and distance range.
inline void expectPointNear(const MapPointRecord& a, const MapPointRecord& b,
                            bool with_appearance = true) {
  EXPECT_EQ(a.id, b.id);
  expectPositionNear(a.position, b.position);
  if (with_appearance) {
    const Eigen::Vector3d unit =
        a.normal.norm() > 0 ? Eigen::Vector3d(a.normal.normalized()) : Eigen::Vector3d::Zero();
    EXPECT_LE((unit - b.normal).cwiseAbs().maxCoeff(), kNormalTolerance);
    EXPECT_EQ(a.descriptor, b.descriptor);
    EXPECT_EQ(a.min_distance, b.min_distance);
    EXPECT_EQ(a.max_distance, b.max_distance);
  } else {
    EXPECT_EQ(b.normal, Eigen::Vector3d::Zero());
    EXPECT_EQ(b.descriptor, Descriptor{});
    EXPECT_EQ(b.min_distance, 0.f);
    EXPECT_EQ(b.max_distance, 0.f);
  }
  EXPECT_EQ(a.reference_keyframe, b.reference_keyframe);
  ASSERT_EQ(a.observations.size(), b.observations.size());
  for (std::size_t i = 0; i < a.observations.size(); ++i) {
    EXPECT_EQ(a.observations[i].keyframe, b.observations[i].keyframe);
    EXPECT_EQ(a.observations[i].keypoint_index, b.observations[i].keypoint_index);
  }
}

}  // namespace edgeslam::test
