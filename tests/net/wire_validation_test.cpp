#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "net/wire_convert.h"
#include "net_test_records.h"

namespace edgeslam {
namespace {

using ::testing::HasSubstr;

v1::KeyFrame validKeyFrame(int n = 10) {
  std::mt19937 rng(11);
  v1::KeyFrame message;
  toProto(test::sampleKeyFrame(test::clientId(3, 9), n, rng), &message);
  return message;
}

template <typename Message>
std::string decodeError(const Message& message) {
  try {
    (void)fromProto(message);
  } catch (const WireError& e) {
    return e.what();
  }
  ADD_FAILURE() << "decoding succeeded";
  return {};
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
  v1::KeyFrame short_y = validKeyFrame();
  short_y.mutable_features()->mutable_keypoints()->mutable_y()->RemoveLast();
  EXPECT_THAT(decodeError(short_y), HasSubstr("keypoints.y has 9 values for 10 keypoints"));

  v1::KeyFrame bad_depth = validKeyFrame();
  bad_depth.mutable_features()->add_depth(1.f);
  EXPECT_THAT(decodeError(bad_depth), HasSubstr("depth has 11 values"));

  v1::KeyFrame bad_size = validKeyFrame();
  bad_size.mutable_features()->mutable_keypoints()->add_size(3.f);
  EXPECT_THAT(decodeError(bad_size), HasSubstr("keypoints.size has 1 values"));

  v1::KeyFrame bad_octave = validKeyFrame();
  bad_octave.mutable_features()->mutable_keypoints()->set_octave(2, 8);
  EXPECT_THAT(decodeError(bad_octave), HasSubstr("octave 8 but the pyramid has 8 levels"));

  v1::KeyFrame nan_x = validKeyFrame();
  nan_x.mutable_features()->mutable_keypoints()->set_x(4, std::numeric_limits<float>::quiet_NaN());
  EXPECT_THAT(decodeError(nan_x), HasSubstr("keypoint 4 has a non-finite"));
}

TEST(WireValidation, PointAssociationsMustNameKeypoints) {
  v1::KeyFrame m = validKeyFrame();
  m.add_point_keypoint_index(10);
  m.add_point_ids(77);
  EXPECT_THAT(decodeError(m), HasSubstr("names keypoint 10 of 10"));

  v1::KeyFrame zero = validKeyFrame();
  zero.set_point_ids(0, 0);
  EXPECT_THAT(decodeError(zero), HasSubstr("point_ids[0] is 0"));

  v1::KeyFrame twice = validKeyFrame();
  twice.add_point_keypoint_index(twice.point_keypoint_index(0));
  twice.add_point_ids(88);
  EXPECT_THAT(decodeError(twice), HasSubstr("associated with two map points"));

  v1::KeyFrame unpaired = validKeyFrame();
  unpaired.add_point_ids(99);
  EXPECT_THAT(decodeError(unpaired), HasSubstr("point keypoint indices for"));
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

TEST(WireValidation, IdsMustBeNonZeroAndCountsBounded) {
  v1::KeyFrame no_id = validKeyFrame();
  no_id.set_id(0);
  EXPECT_THAT(decodeError(no_id), HasSubstr("id is 0"));

  v1::KeyFrame huge;
  huge.set_id(1);
  *huge.mutable_t_cw() = validKeyFrame().t_cw();
  huge.mutable_features()->mutable_keypoints()->mutable_x()->Resize(20001, 1.f);
  EXPECT_THAT(decodeError(huge), HasSubstr("20001 keypoints exceed the limit of 20000"));

  std::mt19937 rng(12);
  v1::MapPoint point;
  toProto(test::samplePoint(5, rng), &point);
  point.add_observation_keyframes(6);
  EXPECT_THAT(decodeError(point), HasSubstr("observation keyframes for"));
  point.add_observation_keypoints(3);
  point.set_observation_keyframes(0, 0);
  EXPECT_THAT(decodeError(point), HasSubstr("observation 0 keyframe is 0"));
}

TEST(WireValidation, MapPointFields) {
  std::mt19937 rng(13);
  v1::MapPoint valid;
  toProto(test::samplePoint(5, rng), &valid);
  v1::MapPoint short_descriptor = valid;
  short_descriptor.mutable_descriptor_bytes()->resize(31);
  EXPECT_THAT(decodeError(short_descriptor), HasSubstr("descriptor holds 31 bytes"));
  v1::MapPoint nan_position = valid;
  nan_position.set_position(1, std::numeric_limits<double>::quiet_NaN());
  EXPECT_THAT(decodeError(nan_position), HasSubstr("position is not finite"));
  v1::MapPoint two_d = valid;
  two_d.mutable_position()->RemoveLast();
  EXPECT_THAT(decodeError(two_d), HasSubstr("position has 2 values, expected 3"));
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
  bad_point.mutable_new_points(1)->set_id(0);
  const std::string error = decodeError(bad_point);
  EXPECT_THAT(error, HasSubstr("keyframe upload 3: map point 0x0: id is 0"));

  v1::MapSlice slice;
  toProto(test::sampleSlice(4, rng), &slice);
  v1::MapSlice bad_mask = slice;
  bad_mask.mutable_masks(0)->set_encoding("gif");
  EXPECT_THAT(decodeError(bad_mask), HasSubstr("encoding 'gif' is neither png nor rle"));
  v1::MapSlice zero_erased = slice;
  zero_erased.add_points_erased(0);
  EXPECT_THAT(decodeError(zero_erased), HasSubstr("points_erased[2] is 0"));
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
}

}  // namespace
}  // namespace edgeslam
