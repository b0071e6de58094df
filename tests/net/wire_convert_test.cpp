#include "net/wire_convert.h"

#include <gtest/gtest.h>

#include <random>

#include "net_test_records.h"
#include "record_expectations.h"

namespace edgeslam {
namespace {

using test::expectKeyFrameEqual;
using test::expectPointEqual;
using test::expectPoseNear;

TEST(WireConvert, PoseRoundTrip) {
  std::mt19937 rng(1);
  for (int i = 0; i < 20; ++i) {
    const SE3d pose = test::samplePose(rng);
    v1::Pose message;
    toProto(pose, &message);
    v1::Pose parsed;
    ASSERT_TRUE(parsed.ParseFromString(message.SerializeAsString()));
    expectPoseNear(pose, fromProto(parsed));
  }
  v1::Pose identity;
  toProto(SE3d::identity(), &identity);
  EXPECT_LE(identity.ByteSizeLong(), 9u);  // zero fields are not sent
}

TEST(WireConvert, KeyFrameRoundTripIsExact) {
  std::mt19937 rng(2);
  for (const bool custom_sizes : {false, true}) {
    const KeyFrameRecord kf =
        test::sampleKeyFrame(test::clientId(3, 42), 300, rng, true, custom_sizes);
    v1::KeyFrame message;
    toProto(kf, &message, WireEncodeOptions{true});
    EXPECT_EQ(message.features().keypoints().size_size(), custom_sizes ? 300 : 0)
        << "ORB-convention sizes are left out";
    EXPECT_EQ(message.point_ids_size(), 150) << "only associated keypoints travel";
    v1::KeyFrame parsed;
    ASSERT_TRUE(parsed.ParseFromString(message.SerializeAsString()));
    expectKeyFrameEqual(kf, fromProto(parsed));
  }
}

TEST(WireConvert, KeyFrameWithoutResponsesOrDepth) {
  std::mt19937 rng(3);
  const KeyFrameRecord kf = test::sampleKeyFrame(test::clientId(3, 43), 50, rng, false);
  v1::KeyFrame message;
  toProto(kf, &message);
  EXPECT_EQ(message.features().keypoints().response_size(), 0);
  const KeyFrameRecord back = fromProto(message);
  expectKeyFrameEqual(kf, back, /*compare_response=*/false);
  for (const cv::KeyPoint& kp : back.features.keypoints) EXPECT_EQ(kp.response, 0.f);
  EXPECT_TRUE(back.features.depth.empty());
}

TEST(WireConvert, EmptyKeyFrameRoundTrip) {
  KeyFrameRecord kf;
  kf.id = 5;
  const KeyFrameRecord back = fromProto([&] {
    v1::KeyFrame m;
    toProto(kf, &m);
    return m;
  }());
  EXPECT_EQ(back.id, 5u);
  EXPECT_TRUE(back.features.keypoints.empty());
  EXPECT_EQ(back.features.descriptors.rows, 0);
  EXPECT_TRUE(back.point_ids.empty());
}

TEST(WireConvert, MapPointRoundTripIsExact) {
  std::mt19937 rng(4);
  const MapPointRecord p = test::samplePoint(test::clientId(0, 99), rng);
  v1::MapPoint message;
  toProto(p, &message);
  v1::MapPoint parsed;
  ASSERT_TRUE(parsed.ParseFromString(message.SerializeAsString()));
  expectPointEqual(p, fromProto(parsed));
}

TEST(WireConvert, UploadRoundTripIsExact) {
  std::mt19937 rng(5);
  const KeyFrameUpload u = test::sampleUpload(7, 200, 30, rng);
  v1::KeyFrameUpload message;
  toProto(u, &message, WireEncodeOptions{true});
  v1::KeyFrameUpload parsed;
  ASSERT_TRUE(parsed.ParseFromString(message.SerializeAsString()));
  const KeyFrameUpload back = fromProto(parsed);
  EXPECT_EQ(back.sequence, u.sequence);
  expectKeyFrameEqual(u.keyframe, back.keyframe);
  ASSERT_EQ(back.new_points.size(), u.new_points.size());
  for (std::size_t i = 0; i < u.new_points.size(); ++i) {
    expectPointEqual(u.new_points[i], back.new_points[i]);
  }
  EXPECT_EQ(back.image_encoding, u.image_encoding);
  EXPECT_EQ(back.image_bytes, u.image_bytes);
  EXPECT_EQ(back.acknowledged_slice, u.acknowledged_slice);
}

TEST(WireConvert, SliceRoundTripIsExact) {
  std::mt19937 rng(6);
  for (const bool with_reference_pose : {true, false}) {
    MapSlice s = test::sampleSlice(11, rng);
    if (!with_reference_pose) s.reference_pose.reset();
    v1::MapSlice message;
    toProto(s, &message, WireEncodeOptions{true});
    v1::MapSlice parsed;
    ASSERT_TRUE(parsed.ParseFromString(message.SerializeAsString()));
    const MapSlice back = fromProto(parsed);
    EXPECT_EQ(back.sequence, s.sequence);
    EXPECT_EQ(back.upload_sequence, s.upload_sequence);
    EXPECT_EQ(back.processed_keyframe, s.processed_keyframe);
    EXPECT_EQ(back.full_resync, s.full_resync);
    ASSERT_EQ(back.keyframes.size(), 1u);
    expectKeyFrameEqual(s.keyframes[0], back.keyframes[0]);
    ASSERT_EQ(back.points_upserted.size(), s.points_upserted.size());
    for (std::size_t i = 0; i < s.points_upserted.size(); ++i) {
      expectPointEqual(s.points_upserted[i], back.points_upserted[i]);
    }
    EXPECT_EQ(back.points_erased, s.points_erased);
    ASSERT_EQ(back.keyframe_poses.size(), s.keyframe_poses.size());
    for (std::size_t i = 0; i < s.keyframe_poses.size(); ++i) {
      EXPECT_EQ(back.keyframe_poses[i].id, s.keyframe_poses[i].id);
      EXPECT_EQ(back.keyframe_poses[i].parent, s.keyframe_poses[i].parent);
      expectPoseNear(back.keyframe_poses[i].T_cw, s.keyframe_poses[i].T_cw);
    }
    EXPECT_EQ(back.keyframes_erased, s.keyframes_erased);
    EXPECT_EQ(back.reference_keyframe, s.reference_keyframe);
    ASSERT_EQ(back.reference_pose.has_value(), with_reference_pose);
    if (with_reference_pose) expectPoseNear(*back.reference_pose, *s.reference_pose);
    ASSERT_EQ(back.masks.size(), 1u);
    EXPECT_EQ(back.masks[0].keyframe, s.masks[0].keyframe);
    EXPECT_EQ(back.masks[0].width, s.masks[0].width);
    EXPECT_EQ(back.masks[0].height, s.masks[0].height);
    EXPECT_EQ(back.masks[0].encoding, s.masks[0].encoding);
    EXPECT_EQ(back.masks[0].bytes, s.masks[0].bytes);
    EXPECT_EQ(back.loops_closed, s.loops_closed);
  }
}

TEST(WireConvert, SessionConfigRoundTrip) {
  SessionConfig config = test::sampleSessionConfig("phone-7");
  config.id_origin = 42;
  v1::OpenSessionRequest message;
  toProto(config, &message);
  const SessionConfig back = fromProto(message);
  EXPECT_EQ(back.client_name, "phone-7");
  const CameraIntrinsics& a = config.camera.intrinsics();
  const CameraIntrinsics& b = back.camera.intrinsics();
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.fx, b.fx);
  EXPECT_EQ(a.fy, b.fy);
  EXPECT_EQ(a.cx, b.cx);
  EXPECT_EQ(a.cy, b.cy);
  EXPECT_EQ(a.distortion.k1, b.distortion.k1);
  EXPECT_EQ(a.distortion.k2, b.distortion.k2);
  EXPECT_EQ(a.distortion.p1, b.distortion.p1);
  EXPECT_EQ(a.distortion.p2, b.distortion.p2);
  EXPECT_EQ(a.distortion.k3, b.distortion.k3);
  EXPECT_EQ(a.depth_factor, b.depth_factor);
  EXPECT_EQ(a.fps, b.fps);
  EXPECT_EQ(back.sensor, Sensor::kRgbd);
  EXPECT_EQ(back.settings.features, 1500);
  EXPECT_EQ(back.settings.pyramid_levels, 6);
  EXPECT_EQ(back.settings.scale_factor, 1.25);
  EXPECT_FALSE(back.settings.semantic);
  EXPECT_EQ(back.id_origin, 42);
}

TEST(WireConvert, OffloadRoundTrip) {
  std::mt19937 rng(7);
  OffloadFrame frame{77, 12.5, "png", {1, 2, 3, 4}, "png", {5, 6}};
  v1::OffloadFrameRequest request;
  toProto(frame, &request);
  const OffloadFrame back = fromProto(request);
  EXPECT_EQ(back.frame_index, 77u);
  EXPECT_EQ(back.timestamp, 12.5);
  EXPECT_EQ(back.image_encoding, "png");
  EXPECT_EQ(back.image_bytes, frame.image_bytes);
  EXPECT_EQ(back.depth_encoding, "png");
  EXPECT_EQ(back.depth_bytes, frame.depth_bytes);

  const OffloadResult result{77, OffloadTrackingState::kOk, test::samplePose(rng), 3.5};
  v1::OffloadFrameReply reply;
  toProto(result, &reply);
  const OffloadResult result_back = fromProto(reply);
  EXPECT_EQ(result_back.frame_index, 77u);
  EXPECT_EQ(result_back.state, OffloadTrackingState::kOk);
  ASSERT_TRUE(result_back.T_cw.has_value());
  expectPoseNear(*result_back.T_cw, *result.T_cw);
  EXPECT_EQ(result_back.server_ms, 3.5);

  v1::OffloadFrameReply lost;
  toProto(OffloadResult{78, OffloadTrackingState::kLost, std::nullopt, 1.0}, &lost);
  EXPECT_FALSE(fromProto(lost).T_cw.has_value());
}

// The figures docs/wire.md quotes: a 1000-keypoint monocular keyframe upload with 100 new points
// and no image, and a slice answering it.
TEST(WireConvert, TypicalMessageSizes) {
  std::mt19937 rng(8);
  KeyFrameUpload upload = test::sampleUpload(1, 1000, 100, rng);
  upload.keyframe.features.depth.clear();
  upload.keyframe.features.right_u.clear();
  upload.image_encoding.clear();
  upload.image_bytes.clear();
  const std::size_t upload_bytes = wireSize(upload);
  // 32 descriptor bytes + 4 floats/varint per keypoint, ~500 associations, 100 points of ~150 B.
  EXPECT_GT(upload_bytes, 32u * 1000u + 13u * 1000u);
  EXPECT_LT(upload_bytes, 75000u);
  MapSlice slice;
  slice.sequence = 1;
  slice.upload_sequence = 1;
  slice.processed_keyframe = upload.keyframe.id;
  for (int i = 0; i < 100; ++i) slice.points_upserted.push_back(test::samplePoint(i + 1, rng));
  for (int i = 0; i < 10; ++i) {
    slice.keyframe_poses.push_back({static_cast<KeyFrameId>(i + 1), test::samplePose(rng), 1});
  }
  slice.points_erased.assign(20, 12345);
  slice.reference_keyframe = 1;
  slice.reference_pose = test::samplePose(rng);
  const std::size_t slice_bytes = wireSize(slice);
  EXPECT_LT(slice_bytes, 25000u);
  std::printf("[ sizes ] upload 1000 kp + 100 points: %zu B; slice 100 points + 10 poses: %zu B\n",
              upload_bytes, slice_bytes);
  upload.keyframe.features.depth.assign(1000, 1.5f);
  upload.keyframe.features.right_u.assign(1000, 100.f);
  std::printf("[ sizes ] same upload with depth + right_u: %zu B\n", wireSize(upload));
  KeyFrameUpload bare = upload;
  bare.new_points.clear();
  bare.keyframe.features.depth.clear();
  bare.keyframe.features.right_u.clear();
  std::printf("[ sizes ] keyframe only (1000 kp, 500 associations): %zu B\n", wireSize(bare));
}

}  // namespace
}  // namespace edgeslam
