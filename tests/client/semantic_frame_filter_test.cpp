// The client's semantic stage on synthetic features: a keyframe mask, once offered, culls the
// features that lie on it in later frames (and only those), follows a moving object, and bad
// masks are refused.
#include "client/semantic_frame_filter.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

// A 30 x 20 lattice of features with distinct random descriptors; those inside `object` are moved
// by `object_shift`, the rest by `background_shift`.
std::shared_ptr<FrameFeatures> lattice(const cv::Rect& object, cv::Point2f object_shift,
                                       cv::Point2f background_shift) {
  auto f = std::make_shared<FrameFeatures>();
  std::mt19937 random(7);
  std::uniform_int_distribution<int> byte(0, 255);
  f->descriptors.create(600, 32, CV_8U);
  int i = 0;
  for (int row = 0; row < 20; ++row) {
    for (int col = 0; col < 30; ++col, ++i) {
      const cv::Point2f base(20.f + 20.f * col, 30.f + 22.f * row);
      const bool on_object = object.contains(cv::Point(cvRound(base.x), cvRound(base.y)));
      f->keypoints.emplace_back(base + (on_object ? object_shift : background_shift), 31.f, 0.f,
                                1.f, 0);
      for (int b = 0; b < 32; ++b) f->descriptors.at<std::uint8_t>(i, b) = byte(random);
    }
  }
  f->grid = FeatureGrid(test::syntheticCamera().undistortedBounds(), f->keypoints);
  return f;
}

cv::Mat1b labelsWith(const cv::Rect& object) {
  cv::Mat1b labels = cv::Mat1b::zeros(480, 640);
  labels(object).setTo(1);
  return labels;
}

TEST(SemanticFrameFilter, WithoutAMaskEveryFeatureIsKept) {
  SemanticFrameFilter filter(test::syntheticCamera());
  const auto features = lattice({}, {}, {});
  const SemanticFrame out = filter.filter(0, features);
  EXPECT_EQ(out.kept, features);
  EXPECT_TRUE(out.mask.empty());
  EXPECT_EQ(out.culled, 0);
}

TEST(SemanticFrameFilter, CullsTheFeaturesOnAMovingObjectAndKeepsTheOthers) {
  const cv::Rect object(200, 150, 120, 160);
  SemanticFilterOptions options;
  options.cull_margin_px = 0;  // exactly the features on the object
  SemanticFrameFilter filter(test::syntheticCamera(), options);
  filter.filter(0, lattice(object, {}, {}));
  filter.filter(1, lattice(object, {4, 2}, {1, 0}));
  filter.offerMask(0, labelsWith(object));  // arrives while frame 2 is due
  const cv::Point2f object_shift(12, 6), background_shift(3, 0);
  const auto frame2 = lattice(object, object_shift, background_shift);
  const SemanticFrame out = filter.filter(2, frame2);
  ASSERT_FALSE(out.mask.empty());
  ASSERT_EQ(out.mask_source_frame, std::optional<std::size_t>(0));
  const cv::Rect moved = object + cv::Point(12, 6);
  // The transferred mask sits on the object's new place.
  EXPECT_GT(cv::countNonZero(out.mask(moved)), 0.95 * moved.area());
  EXPECT_LT(cv::countNonZero(out.mask) - cv::countNonZero(out.mask(moved)), 0.05 * moved.area());
  int on_object = 0;
  for (const cv::KeyPoint& kp : frame2->keypoints) on_object += moved.contains(kp.pt);
  EXPECT_EQ(out.culled, on_object);
  EXPECT_EQ(out.kept->size(), frame2->size() - static_cast<std::size_t>(on_object));
  for (const cv::KeyPoint& kp : out.kept->keypoints) EXPECT_FALSE(moved.contains(kp.pt)) << kp.pt;
  const SemanticFilterCounters counters = filter.counters();
  EXPECT_EQ(counters.masks_applied, 1u);
  EXPECT_EQ(counters.features_culled, static_cast<std::size_t>(on_object));
}

TEST(SemanticFrameFilter, AnEmptyKeyframeMaskClearsTheOldOne) {
  const cv::Rect object(200, 150, 120, 160);
  SemanticFrameFilter filter(test::syntheticCamera());
  filter.filter(0, lattice(object, {}, {}));
  filter.offerMask(0, labelsWith(object));
  EXPECT_GT(filter.filter(1, lattice(object, {}, {})).culled, 0);
  filter.offerMask(1, cv::Mat1b::zeros(480, 640));
  const SemanticFrame out = filter.filter(2, lattice(object, {}, {}));
  EXPECT_EQ(out.culled, 0);
  EXPECT_EQ(cv::countNonZero(out.mask), 0);
}

TEST(SemanticFrameFilter, AnOlderKeyframesMaskAfterANewerOneIsLeftOut) {
  // Keyframes are segmented newest first: the mask of keyframe 1 arrives after keyframe 3's.
  const cv::Rect newer(200, 150, 120, 160);
  const cv::Rect older(20, 20, 100, 100);
  SemanticFrameFilter filter(test::syntheticCamera());
  for (std::size_t i = 0; i < 4; ++i) filter.filter(i, lattice(newer, {}, {}));
  filter.offerMask(3, labelsWith(newer));
  filter.offerMask(1, labelsWith(older));
  const SemanticFrame out = filter.filter(4, lattice(newer, {}, {}));
  EXPECT_EQ(out.mask_source_frame, std::optional<std::size_t>(3));
  EXPECT_EQ(cv::countNonZero(out.mask(older)), 0);
  EXPECT_EQ(filter.counters().masks_superseded, 1u);
  EXPECT_EQ(filter.counters().masks_applied, 1u);
}

TEST(SemanticFrameFilter, AFramesOwnMaskOfferedBeforeItIsFilteredIsAppliedToItAndCarriedOn) {
  // The first frame of a map with depth is segmented before its features are culled.
  const cv::Rect object(200, 150, 120, 160);
  SemanticFilterOptions options;
  options.cull_margin_px = 0;
  SemanticFrameFilter filter(test::syntheticCamera(), options);
  filter.offerMask(0, labelsWith(object));
  const auto frame0 = lattice(object, {}, {});
  const SemanticFrame first = filter.filter(0, frame0);
  ASSERT_EQ(first.mask_source_frame, std::optional<std::size_t>(0));
  int on_object = 0;
  for (const cv::KeyPoint& kp : frame0->keypoints) on_object += object.contains(kp.pt);
  ASSERT_GT(on_object, 0);
  EXPECT_EQ(first.culled, on_object);
  EXPECT_EQ(filter.typicalMaskDelayFrames(), std::optional<std::size_t>(0));
  EXPECT_EQ(filter.counters().masks_too_old, 0u);
  // The next frame gets it transferred; the keyframe's own later mask of the same frame adds
  // nothing.
  filter.offerMask(0, labelsWith(object));
  const SemanticFrame next = filter.filter(1, lattice(object, {4, 2}, {1, 0}));
  EXPECT_EQ(next.mask_source_frame, std::optional<std::size_t>(0));
  EXPECT_GT(next.culled, 0);
  EXPECT_EQ(filter.counters().masks_applied, 1u);
}

TEST(SemanticFrameFilter, RefusesMisSizedMasksAndCountsMasksPastTheHistory) {
  SemanticFilterOptions options;
  options.history_frames = 5;
  SemanticFrameFilter filter(test::syntheticCamera(), options);
  EXPECT_THROW(filter.offerMask(0, cv::Mat1b::zeros(240, 320)), std::invalid_argument);
  EXPECT_THROW(filter.offerMask(0, cv::Mat1b()), std::invalid_argument);
  for (std::size_t i = 0; i < 10; ++i) filter.filter(i, lattice({}, {}, {}));
  filter.offerMask(2, labelsWith({10, 10, 50, 50}));
  EXPECT_EQ(filter.counters().masks_too_old, 1u);
  EXPECT_TRUE(filter.filter(10, lattice({}, {}, {})).mask.empty());
}

TEST(SemanticFrameFilter, TypicalMaskDelayIsTheMedianOfTheLastFive) {
  SemanticFrameFilter filter(test::syntheticCamera());
  EXPECT_EQ(filter.typicalMaskDelayFrames(), std::nullopt);
  const cv::Rect object(200, 150, 120, 160);
  // Masks of keyframes 0, 10, 20, ... arriving 1, 1, 2, 6, 7 and then 3 frames late.
  const std::size_t delays[] = {1, 1, 2, 6, 7, 3};
  std::size_t frame_index = 0;
  for (std::size_t k = 0; k < 6; ++k) {
    const std::size_t keyframe = 10 * k;
    while (frame_index <= keyframe + delays[k]) {
      filter.filter(frame_index++, lattice(object, {}, {}));
    }
    filter.offerMask(keyframe, labelsWith(object));
  }
  EXPECT_EQ(filter.typicalMaskDelayFrames(), std::optional<std::size_t>(3));  // of 1 2 6 7 3
}

}  // namespace
}  // namespace edgeslam
