#pragma once
// Field-by-field equality of wire records: exact for ids, integers, floats and bytes; 1e-12 for
// the doubles of poses (re-normalised quaternions).
#include <gtest/gtest.h>

#include "map/map_records.h"

namespace edgeslam::test {

inline void expectPoseNear(const SE3d& a, const SE3d& b) {
  EXPECT_LT((a.rotation().coeffs() - b.rotation().coeffs()).norm(), 1e-12);
  EXPECT_LT((a.translation() - b.translation()).norm(), 1e-12);
}

inline void expectKeyFrameEqual(const KeyFrameRecord& a, const KeyFrameRecord& b,
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
    EXPECT_EQ(ka.pt.x, kb.pt.x) << i;
    EXPECT_EQ(ka.pt.y, kb.pt.y) << i;
    EXPECT_EQ(ka.angle, kb.angle) << i;
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
  EXPECT_EQ(fa.depth, fb.depth);
  EXPECT_EQ(fa.right_u, fb.right_u);
  EXPECT_EQ(fa.pyramid_levels, fb.pyramid_levels);
  EXPECT_EQ(fa.scale_factor, fb.scale_factor);
  EXPECT_EQ(fa.bf, fb.bf);
  EXPECT_EQ(a.point_ids, b.point_ids);
}

inline void expectPointEqual(const MapPointRecord& a, const MapPointRecord& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_LT((a.position - b.position).norm(), 1e-12);
  EXPECT_LT((a.normal - b.normal).norm(), 1e-12);
  EXPECT_EQ(a.descriptor, b.descriptor);
  EXPECT_EQ(a.min_distance, b.min_distance);
  EXPECT_EQ(a.max_distance, b.max_distance);
  EXPECT_EQ(a.reference_keyframe, b.reference_keyframe);
  ASSERT_EQ(a.observations.size(), b.observations.size());
  for (std::size_t i = 0; i < a.observations.size(); ++i) {
    EXPECT_EQ(a.observations[i].keyframe, b.observations[i].keyframe);
    EXPECT_EQ(a.observations[i].keypoint_index, b.observations[i].keypoint_index);
  }
}

}  // namespace edgeslam::test
