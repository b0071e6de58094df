#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "net_test_records.h"
#include "wire/wire_convert.h"
#include "wire_decode_error.h"

namespace edgeslam {
namespace {

using test::decodeError;
using ::testing::HasSubstr;

v1::KeyFrame validKeyFrame(int n = 10) {
  std::mt19937 rng(11);
  v1::KeyFrame message;
  toProto(test::sampleKeyFrame(test::clientId(3, 9), n, rng), &message);
  return message;
}

TEST(WireValidation, ValidKeyFrameDecodes) {
  EXPECT_NO_THROW((void)fromProto(validKeyFrame()));
}

TEST(WireValidation, DescriptorBytesMustMatchKeypoints) {
  v1::KeyFrame m = validKeyFrame();
  m.mutable_features()->mutable_descriptors()->resize(10 * 32 - 1);
  const std::string error = decodeError(m);
  EXPECT_THAT(error, HasSubstr("descriptors hold 319 bytes, expected 32 x 10"));
  EXPECT_THAT(error, HasSubstr("keyframe 0x300000000000009"));
}

TEST(WireValidation, PerKeypointArraysMustBeConsistent) {
  ASSERT_EQ(validKeyFrame().features().keypoints().coordinate_bytes(), 2u);
  v1::KeyFrame short_y = validKeyFrame();
  short_y.mutable_features()->mutable_keypoints()->mutable_y()->pop_back();
  EXPECT_THAT(decodeError(short_y), HasSubstr("keypoints.y holds 19 bytes, expected 10 x 2 = 20"));

  v1::KeyFrame short_angle = validKeyFrame();
  short_angle.mutable_features()->mutable_keypoints()->mutable_angle()->append("x");
  EXPECT_THAT(decodeError(short_angle), HasSubstr("keypoints.angle holds 11 bytes"));

  v1::KeyFrame two_byte_angles = validKeyFrame();  // the layout of old senders: 2 bytes, no width
  two_byte_angles.mutable_features()->mutable_keypoints()->set_angle_bytes(0);
  EXPECT_THAT(decodeError(two_byte_angles), HasSubstr("keypoints.angle holds 10 bytes"));

  v1::KeyFrame three_byte_angles = validKeyFrame();
  three_byte_angles.mutable_features()->mutable_keypoints()->set_angle_bytes(3);
  EXPECT_THAT(decodeError(three_byte_angles), HasSubstr("angle_bytes 3 is neither 1 nor 2"));

  v1::KeyFrame wide = validKeyFrame();
  wide.mutable_features()->mutable_keypoints()->set_coordinate_bytes(5);
  EXPECT_THAT(decodeError(wide), HasSubstr("coordinate_bytes 5 outside 1..4"));

  v1::KeyFrame bad_depth = validKeyFrame();
  ASSERT_EQ(bad_depth.features().depth_mm().size(), 20u);
  bad_depth.mutable_features()->mutable_depth_mm()->append("ab");
  EXPECT_THAT(decodeError(bad_depth), HasSubstr("depth_mm holds 22 bytes, expected 10 x 2"));

  v1::KeyFrame two_depths = validKeyFrame();
  two_depths.mutable_features()->add_depth(1.f);
  EXPECT_THAT(decodeError(two_depths), HasSubstr("both as depth_mm and as floats"));

  v1::KeyFrame bad_size = validKeyFrame();
  bad_size.mutable_features()->mutable_keypoints()->add_size(3.f);
  EXPECT_THAT(decodeError(bad_size), HasSubstr("keypoints.size has 1 values"));

  v1::KeyFrame bad_octave = validKeyFrame();
  (*bad_octave.mutable_features()->mutable_keypoints()->mutable_octave())[2] = 8;
  EXPECT_THAT(decodeError(bad_octave), HasSubstr("octave 8 but the pyramid has 8 levels"));

  v1::KeyFrame runs = validKeyFrame();
  v1::KeyPoints* keypoints = runs.mutable_features()->mutable_keypoints();
  keypoints->clear_octave();
  keypoints->add_octave_runs(4);
  keypoints->add_octave_runs(5);
  EXPECT_THAT(decodeError(runs), HasSubstr("octave_runs add up to 9 for 10 keypoints"));
  keypoints->add_octave_runs(1);
  EXPECT_EQ(fromProto(runs).features.keypoints[9].octave, 2);
  for (int level = 3; level < 9; ++level) keypoints->add_octave_runs(0);
  EXPECT_THAT(decodeError(runs), HasSubstr("octave_runs has 9 levels but the pyramid has 8"));
  v1::KeyFrame both = validKeyFrame();
  both.mutable_features()->mutable_keypoints()->add_octave_runs(10);
  EXPECT_THAT(decodeError(both), HasSubstr("both octave and octave_runs"));

  v1::KeyFrame nan_right_u = validKeyFrame();
  ASSERT_FALSE(nan_right_u.features().right_u_from_depth());
  nan_right_u.mutable_features()->set_right_u(4, std::numeric_limits<float>::quiet_NaN());
  EXPECT_THAT(decodeError(nan_right_u), HasSubstr("right_u of keypoint 4 is NaN"));

  v1::KeyFrame rebuilt_without_depth = validKeyFrame();
  rebuilt_without_depth.mutable_features()->clear_right_u();
  rebuilt_without_depth.mutable_features()->clear_depth_mm();
  rebuilt_without_depth.mutable_features()->set_right_u_from_depth(true);
  EXPECT_THAT(decodeError(rebuilt_without_depth), HasSubstr("rebuilt from depth, but no depth"));
}

TEST(WireValidation, PointAssociationsMustNameKeypoints) {
  v1::KeyFrame m = validKeyFrame();
  ASSERT_EQ(m.point_keypoint_gaps_size(), 5);  // keypoints 0, 2, 4, 6, 8
  m.add_point_keypoint_gaps(1);
  m.add_point_id_deltas(77);
  EXPECT_THAT(decodeError(m), HasSubstr("association 5 names keypoint 10 of 10"));

  v1::KeyFrame zero = validKeyFrame();
  // The first id is sent relative to the keyframe id.
  zero.set_point_id_deltas(0, -static_cast<std::int64_t>(zero.id()));
  EXPECT_THAT(decodeError(zero), HasSubstr("point id of association 0 is 0"));

  v1::KeyFrame unpaired = validKeyFrame();
  unpaired.add_point_id_deltas(99);
  EXPECT_THAT(decodeError(unpaired), HasSubstr("5 point keypoint gaps for 6 point id deltas"));
}

TEST(WireValidation, PosesMustBeFiniteAndNormalisable) {
  v1::KeyFrame nan_pose = validKeyFrame();
  nan_pose.mutable_t_cw()->set_tx(std::numeric_limits<double>::infinity());
  EXPECT_THAT(decodeError(nan_pose), HasSubstr("T_cw: pose is not finite"));

  v1::KeyFrame zero_q = validKeyFrame();
  v1::Pose* pose = zero_q.mutable_t_cw();
  pose->set_qw(0);
  pose->set_qx(0);
  pose->set_qy(0);
  pose->set_qz(0);
  EXPECT_THAT(decodeError(zero_q), HasSubstr("cannot be normalised"));

  v1::KeyFrame no_pose = validKeyFrame();
  no_pose.clear_t_cw();
  EXPECT_THAT(decodeError(no_pose), HasSubstr("T_cw is missing"));

  v1::Pose scaled;
  scaled.set_qw(2.0);
  EXPECT_EQ(fromProto(scaled).rotation().w(), 1.0) << "a non-unit quaternion is normalised";
}

v1::MapPoints validPoints(bool with_appearance = true) {
  std::mt19937 rng(13);
  v1::MapPoints points;
  toProto({test::samplePoint(5, rng), test::samplePoint(9, rng)}, &points, with_appearance);
  return points;
}

TEST(WireValidation, IdsMustBeNonZeroAndCountsBounded) {
  v1::KeyFrame no_id = validKeyFrame();
  no_id.set_id(0);
  EXPECT_THAT(decodeError(no_id), HasSubstr("id is 0"));

  v1::KeyFrame huge;
  huge.set_id(1);
  *huge.mutable_t_cw() = validKeyFrame().t_cw();
  huge.mutable_features()->set_pyramid_levels(8);
  huge.mutable_features()->set_scale_factor(1.2);
  huge.mutable_features()->mutable_keypoints()->set_count(20001);
  EXPECT_THAT(decodeError(huge), HasSubstr("20001 keypoints exceed the limit of 20000"));

  v1::MapPoints extra = validPoints();
  extra.add_observation_keyframe_deltas(6);
  EXPECT_THAT(decodeError(extra), HasSubstr("observation counts add up to 8, but 9"));

  v1::MapPoints zero_keyframe = validPoints();
  // The first observation is sent relative to the point id (5).
  zero_keyframe.set_observation_keyframe_deltas(0, -5);
  EXPECT_THAT(decodeError(zero_keyframe), HasSubstr("map point 0x5: observation 0 keyframe is 0"));

  v1::MapPoints many = validPoints();
  many.set_observation_counts(0, 10001);
  EXPECT_THAT(decodeError(many), HasSubstr("10001 observations of a point exceed the limit"));

  v1::MapPoints far_keypoint = validPoints();
  far_keypoint.set_observation_keypoints(1, 20000);
  EXPECT_THAT(decodeError(far_keypoint), HasSubstr("observation 1 names keypoint 20000"));

  v1::MapPoints zero_id = validPoints();
  zero_id.set_id_deltas(1, -5);
  EXPECT_THAT(decodeError(zero_id), HasSubstr("map point 0x0: id is 0"));

  v1::MapPoints short_ids = validPoints();
  short_ids.mutable_id_deltas()->RemoveLast();
  EXPECT_THAT(decodeError(short_ids), HasSubstr("points.id_deltas has 1 values for 2 points"));
}

TEST(WireValidation, MapPointFields) {
  const v1::MapPoints valid = validPoints();
  EXPECT_EQ(fromProto(valid).size(), 2u);
  v1::MapPoints short_descriptor = valid;
  short_descriptor.mutable_descriptors()->pop_back();
  EXPECT_THAT(decodeError(short_descriptor), HasSubstr("points.descriptors holds 63 bytes"));
  v1::MapPoints nan_position = valid;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  nan_position.mutable_positions()->replace(16, 4, reinterpret_cast<const char*>(&nan), 4);
  EXPECT_THAT(decodeError(nan_position), HasSubstr("map point 0x9: position is not finite"));
  v1::MapPoints short_positions = valid;
  short_positions.mutable_positions()->resize(20);
  EXPECT_THAT(decodeError(short_positions), HasSubstr("points.positions holds 20 bytes"));
  v1::MapPoints half_appearance = valid;
  half_appearance.clear_normals();
  EXPECT_THAT(decodeError(half_appearance), HasSubstr("points.normals holds 0 bytes"));
  v1::MapPoints negative_range = valid;
  const float minus_one = -1.f;
  negative_range.mutable_distances()->replace(0, 4, reinterpret_cast<const char*>(&minus_one), 4);
  EXPECT_THAT(decodeError(negative_range), HasSubstr("distance range [-1"));
  const std::vector<MapPointRecord> bare = fromProto(validPoints(false));
  ASSERT_EQ(bare.size(), 2u);
  EXPECT_EQ(bare[0].descriptor, Descriptor{});
}

TEST(WireValidation, UploadAndSliceEnvelopes) {
  std::mt19937 rng(14);
  v1::KeyFrameUpload upload;
  toProto(test::sampleUpload(3, 10, 2, rng), &upload);
  v1::KeyFrameUpload no_sequence = upload;
  no_sequence.set_sequence(0);
  EXPECT_THAT(decodeError(no_sequence), HasSubstr("sequence is 0"));
  v1::KeyFrameUpload no_image = upload;
  no_image.clear_image();
  EXPECT_THAT(decodeError(no_image), HasSubstr("image encoding 'jpeg' with 0 image bytes"));
  v1::KeyFrameUpload bad_point = upload;
  const std::int64_t second = bad_point.new_points().id_deltas(1);
  bad_point.mutable_new_points()->set_id_deltas(
      1, second - static_cast<std::int64_t>(test::clientId(3, 50001)));
  EXPECT_THAT(decodeError(bad_point),
              HasSubstr("keyframe upload 3: new points: map point 0x0: id is 0"));

  v1::MapSlice slice;
  toProto(test::sampleSlice(4, rng), &slice);
  v1::MapSlice bad_mask = slice;
  bad_mask.mutable_masks(0)->set_encoding("gif");
  EXPECT_THAT(decodeError(bad_mask),
              HasSubstr("encoding 'gif' is neither png/N (N 1..64) nor empty"));
  bad_mask.mutable_masks(0)->set_encoding("png/0");
  EXPECT_THAT(decodeError(bad_mask), HasSubstr("encoding 'png/0' is neither"));
  bad_mask.mutable_masks(0)->set_encoding("empty");
  EXPECT_THAT(decodeError(bad_mask), HasSubstr("encoding 'empty' with 5 data bytes"));
  bad_mask.mutable_masks(0)->set_encoding("png/4");
  bad_mask.mutable_masks(0)->set_segmentation_ms(-1.f);
  EXPECT_THAT(decodeError(bad_mask), HasSubstr("segmentation time -1 ms"));
  v1::MapSlice zero_erased = slice;
  // Back from the last erased id to 0.
  zero_erased.add_points_erased(-static_cast<std::int64_t>(test::clientId(0, 5)));
  EXPECT_THAT(decodeError(zero_erased), HasSubstr("points_erased[2] is 0"));
  v1::MapSlice zero_evicted = slice;
  zero_evicted.add_keyframes_evicted(-static_cast<std::int64_t>(test::clientId(0, 1)));
  EXPECT_THAT(decodeError(zero_evicted), HasSubstr("keyframes_evicted[3] is 0"));
  v1::MapSlice flat_pose = slice;
  flat_pose.mutable_keyframe_poses()->mutable_poses()->replace(0, 16, std::string(16, '\0'));
  EXPECT_THAT(decodeError(flat_pose),
              HasSubstr("keyframe pose 0x300000000000008: pose quaternion has norm 0"));
  v1::MapSlice short_poses = slice;
  short_poses.mutable_keyframe_poses()->mutable_poses()->pop_back();
  EXPECT_THAT(decodeError(short_poses), HasSubstr("keyframe_poses.poses holds 55 bytes"));
  v1::MapSlice moved_nan = slice;
  const float inf = std::numeric_limits<float>::infinity();
  moved_nan.mutable_point_positions()->mutable_positions()->replace(
      12, 4, reinterpret_cast<const char*>(&inf), 4);
  EXPECT_THAT(decodeError(moved_nan),
              HasSubstr("map slice 4: moved point 0x300000000000191: position is not finite"));
  v1::MapSlice bad_slice_point = slice;
  bad_slice_point.mutable_points_upserted()->mutable_normals()->pop_back();
  EXPECT_THAT(decodeError(bad_slice_point),
              HasSubstr("map slice 4: upserted points: points.normals"));
}

TEST(WireValidation, SessionAndOffloadRequests) {
  v1::OpenSessionRequest request;
  toProto(test::sampleSessionConfig(), &request);
  v1::OpenSessionRequest bad_camera = request;
  bad_camera.mutable_camera()->set_fx(0.0);
  EXPECT_THAT(decodeError(bad_camera), HasSubstr("camera:"));
  v1::OpenSessionRequest no_sensor = request;
  no_sensor.set_sensor(v1::SENSOR_UNSPECIFIED);
  EXPECT_THAT(decodeError(no_sensor), HasSubstr("sensor 0 is not mono, rgbd or stereo"));
  v1::OpenSessionRequest bad_levels = request;
  bad_levels.mutable_settings()->set_pyramid_levels(0);
  EXPECT_THAT(decodeError(bad_levels), HasSubstr("settings.pyramid_levels 0"));
  v1::OpenSessionRequest huge_window = request;
  huge_window.mutable_settings()->set_client_map_keyframes(4000000000u);
  EXPECT_THAT(decodeError(huge_window), HasSubstr("settings.client_map_keyframes 4000000000"));

  v1::OffloadFrameRequest frame;
  frame.set_image_encoding("bmp");
  frame.set_image("x");
  EXPECT_THAT(decodeError(frame), HasSubstr("image encoding 'bmp'"));
}

TEST(WireValidation, UnencodableRecordsAreRefused) {
  std::mt19937 rng(15);
  KeyFrameRecord kf = test::sampleKeyFrame(1, 10, rng);
  kf.features.descriptors = cv::Mat(9, 32, CV_8UC1);
  v1::KeyFrame message;
  EXPECT_THROW(toProto(kf, &message), WireError);
  kf = test::sampleKeyFrame(1, 10, rng);
  kf.point_ids.pop_back();
  EXPECT_THROW(toProto(kf, &message), WireError);
  kf = test::sampleKeyFrame(1, 10, rng);
  kf.features.keypoints[3].pt.x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(toProto(kf, &message), WireError);
  kf = test::sampleKeyFrame(1, 10, rng);
  kf.features.keypoints[3].angle = std::numeric_limits<float>::infinity();
  EXPECT_THROW(toProto(kf, &message), WireError);
  kf = test::sampleKeyFrame(1, 10, rng);
  kf.features.keypoints[3].octave = -1;
  EXPECT_THROW(toProto(kf, &message), WireError);
  std::vector<MapPointRecord> points{test::samplePoint(4, rng)};
  points[0].position.x() = 1e39;  // beyond float32
  v1::MapPoints point_message;
  EXPECT_THROW(toProto(points, &point_message, true), WireError);
}

}  // namespace
}  // namespace edgeslam
