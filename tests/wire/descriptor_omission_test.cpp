// Keyframe uploads leave out the descriptors of keypoints whose point the edge already has (any
// associated point that is not one of the upload's new points): 32 bytes fewer per such keypoint,
// decoded as zero rows flagged in descriptor_omitted for the edge to fill. Slices and uploads with
// the option off keep every descriptor.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>

#include "net_test_records.h"
#include "record_expectations.h"
#include "wire/wire_convert.h"
#include "wire_decode_error.h"

namespace edgeslam {
namespace {

using test::decodeError;
using ::testing::HasSubstr;

constexpr int kKeypoints = 100;

WireEncodeOptions omitting() {
  WireEncodeOptions options;
  options.omit_known_point_descriptors = true;
  return options;
}

// sampleUpload associates every even keypoint with a point the upload does not carry; here the
// first three of them name new points of the upload instead, whose descriptors must travel.
KeyFrameUpload uploadWithKnownAndNewPoints() {
  std::mt19937 rng(5);
  KeyFrameUpload upload = test::sampleUpload(4, kKeypoints, 5, rng);
  for (int k = 0; k < 3; ++k) upload.keyframe.point_ids[2 * k] = upload.new_points[k].id;
  return upload;
}

// Keypoints whose descriptor stays home: associated, and not with a new point.
std::vector<bool> expectedOmitted(const KeyFrameUpload& upload) {
  std::vector<bool> omitted(upload.keyframe.point_ids.size(), false);
  for (std::size_t i = 0; i < omitted.size(); ++i) {
    const MapPointId id = upload.keyframe.point_ids[i];
    omitted[i] = id != kInvalidId && i >= 6;  // the first three associations name new points
  }
  return omitted;
}

std::size_t countOf(const std::vector<bool>& flags) {
  return static_cast<std::size_t>(std::count(flags.begin(), flags.end(), true));
}

TEST(DescriptorOmission, UploadShrinksBy32BytesPerKnownPointKeypoint) {
  const KeyFrameUpload upload = uploadWithKnownAndNewPoints();
  const std::vector<bool> omitted = expectedOmitted(upload);
  const std::size_t known = countOf(omitted);
  ASSERT_EQ(known, kKeypoints / 2 - 3);

  v1::KeyFrameUpload full;
  v1::KeyFrameUpload lean;
  toProto(upload, &full);
  toProto(upload, &lean, omitting());
  EXPECT_FALSE(full.keyframe().known_point_descriptors_omitted());
  EXPECT_TRUE(lean.keyframe().known_point_descriptors_omitted());
  EXPECT_EQ(full.keyframe().features().descriptors().size(), 32u * kKeypoints);
  EXPECT_EQ(lean.keyframe().features().descriptors().size(), 32u * (kKeypoints - known));
  // The flag costs its 2 bytes; the descriptors' length prefix keeps its 2.
  EXPECT_EQ(wireSize(full) - wireSize(lean), 32u * known - 2u);
  EXPECT_EQ(wireSize(upload, omitting()), wireSize(lean));
}

TEST(DescriptorOmission, DecodedUploadFlagsTheLeftOutRowsAsZeros) {
  const KeyFrameUpload upload = uploadWithKnownAndNewPoints();
  const std::vector<bool> omitted = expectedOmitted(upload);
  v1::KeyFrameUpload message;
  toProto(upload, &message, omitting());
  const KeyFrameUpload decoded = fromProto(message);
  const KeyFrameRecord& kf = decoded.keyframe;
  EXPECT_EQ(kf.features.descriptor_omitted, omitted);
  EXPECT_EQ(kf.point_ids, upload.keyframe.point_ids);
  ASSERT_EQ(kf.features.descriptors.rows, kKeypoints);
  for (int i = 0; i < kKeypoints; ++i) {
    const cv::Mat row = kf.features.descriptors.row(i);
    if (omitted[static_cast<std::size_t>(i)]) {
      EXPECT_EQ(cv::countNonZero(row), 0) << i;
    } else {
      EXPECT_EQ(cv::norm(row, upload.keyframe.features.descriptors.row(i), cv::NORM_HAMMING), 0.0)
          << i;
    }
  }
  // Everything else as without the option.
  ASSERT_EQ(decoded.new_points.size(), upload.new_points.size());
  KeyFrameRecord expected = upload.keyframe;
  KeyFrameRecord got = kf;
  got.features.descriptors = expected.features.descriptors;  // compared above
  test::expectKeyFrameNear(expected, got, /*compare_response=*/false);
}

TEST(DescriptorOmission, OffByDefaultTheUploadIsLossless) {
  const KeyFrameUpload upload = uploadWithKnownAndNewPoints();
  v1::KeyFrameUpload message;
  toProto(upload, &message);
  const KeyFrameUpload decoded = fromProto(message);
  EXPECT_TRUE(decoded.keyframe.features.descriptor_omitted.empty());
  EXPECT_EQ(cv::norm(decoded.keyframe.features.descriptors, upload.keyframe.features.descriptors,
                     cv::NORM_HAMMING),
            0.0);
}

TEST(DescriptorOmission, NothingToLeaveOutSetsNoFlag) {
  KeyFrameUpload upload = uploadWithKnownAndNewPoints();
  for (std::size_t i = 6; i < upload.keyframe.point_ids.size(); ++i) {
    upload.keyframe.point_ids[i] = kInvalidId;  // only new points remain associated
  }
  v1::KeyFrameUpload message;
  toProto(upload, &message, omitting());
  EXPECT_FALSE(message.keyframe().known_point_descriptors_omitted());
  EXPECT_EQ(message.keyframe().features().descriptors().size(), 32u * kKeypoints);
  EXPECT_TRUE(fromProto(message).keyframe.features.descriptor_omitted.empty());
}

TEST(DescriptorOmission, SliceKeyFramesKeepEveryDescriptor) {
  std::mt19937 rng(9);
  const MapSlice slice = test::sampleSlice(3, rng);
  ASSERT_FALSE(slice.keyframes.empty());
  v1::MapSlice message;
  toProto(slice, &message, omitting());
  for (const v1::KeyFrame& kf : message.keyframes()) {
    EXPECT_FALSE(kf.known_point_descriptors_omitted());
    EXPECT_EQ(kf.features().descriptors().size(), 32u * kf.features().keypoints().count());
  }
  const MapSlice decoded = fromProto(message);
  for (const KeyFrameRecord& kf : decoded.keyframes) {
    EXPECT_TRUE(kf.features.descriptor_omitted.empty());
  }
}

TEST(DescriptorOmission, DecodedUploadReencodesOnlyWithTheSameRowsLeftOut) {
  const KeyFrameUpload upload = uploadWithKnownAndNewPoints();
  v1::KeyFrameUpload message;
  toProto(upload, &message, omitting());
  const KeyFrameUpload decoded = fromProto(message);
  v1::KeyFrameUpload again;
  toProto(decoded, &again, omitting());
  EXPECT_EQ(again.keyframe().features().descriptors(), message.keyframe().features().descriptors());
  // Sending every row would put the left-out rows (zeros after decoding) on the wire as
  // descriptors: refused.
  v1::KeyFrameUpload all;
  try {
    toProto(decoded, &all);
    ADD_FAILURE() << "encoding succeeded";
  } catch (const WireError& e) {
    EXPECT_THAT(std::string(e.what()), HasSubstr("keypoint 6 has no descriptor"));
  }
  KeyFrameUpload short_flags = decoded;
  short_flags.keyframe.features.descriptor_omitted.pop_back();
  EXPECT_THROW(toProto(short_flags, &all, omitting()), WireError);
}

TEST(DescriptorOmission, MalformedMessagesAreWireErrors) {
  const KeyFrameUpload upload = uploadWithKnownAndNewPoints();
  const std::size_t known = countOf(expectedOmitted(upload));
  v1::KeyFrameUpload lean;
  toProto(upload, &lean, omitting());

  v1::KeyFrameUpload one_row_short = lean;
  one_row_short.mutable_keyframe()->mutable_features()->mutable_descriptors()->resize(
      32 * (kKeypoints - known - 1));
  const std::string short_error = decodeError(one_row_short);
  EXPECT_THAT(short_error, HasSubstr("keyframe upload 4: keyframe 0x3000000000003ec"));
  EXPECT_THAT(short_error,
              HasSubstr("expected 32 x " + std::to_string(kKeypoints - known) + " keypoints"));
  EXPECT_THAT(short_error, HasSubstr("travel without theirs"));

  // The flag on a message that carries every row (an encoder that forgot to leave them out).
  v1::KeyFrameUpload all_rows_flagged;
  toProto(upload, &all_rows_flagged);
  all_rows_flagged.mutable_keyframe()->set_known_point_descriptors_omitted(true);
  EXPECT_THAT(decodeError(all_rows_flagged), HasSubstr("descriptors hold 3200 bytes"));

  // Flagged, but every association names a new point: nothing could have been left out.
  KeyFrameUpload only_new = upload;
  for (std::size_t i = 6; i < only_new.keyframe.point_ids.size(); ++i) {
    only_new.keyframe.point_ids[i] = kInvalidId;
  }
  v1::KeyFrameUpload nothing_known;
  toProto(only_new, &nothing_known, omitting());
  nothing_known.mutable_keyframe()->set_known_point_descriptors_omitted(true);
  EXPECT_THAT(decodeError(nothing_known), HasSubstr("no keypoint names a point other than"));

  // Only uploads may leave descriptors out: a slice's keyframe may not.
  std::mt19937 rng(9);
  v1::MapSlice slice;
  toProto(test::sampleSlice(3, rng), &slice);
  slice.mutable_keyframes(0)->set_known_point_descriptors_omitted(true);
  EXPECT_THAT(decodeError(slice), HasSubstr("only a keyframe upload may leave"));
}

}  // namespace
}  // namespace edgeslam
