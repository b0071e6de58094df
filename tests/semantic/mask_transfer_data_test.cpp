// Mask transfer on real pixels: a person cut out of a shared photo is pasted into a 7-Scenes frame;
// the next frame moves the background and the person by different known similarities. ORB matches
// between the two frames drive the transfer, which must land on the person's true new place.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "people_photos.h"
#include "semantic/mask_query.h"
#include "semantic/mask_transfer.h"
#include "support/shared_data.h"
#include "util/timing_stats.h"

namespace edgeslam {
namespace {

struct PastedPerson {
  cv::Mat pixels;  // BGR, 640x480, zero outside the person
  cv::Mat1b mask;  // 255 on the person
};

// The best-scoring pixel-masked person of bus.jpg, scaled to 300 px tall, placed at x = 220, y =
// 150.
PastedPerson personFromBusPhoto() {
  const auto& photo = test::segmentedPhoto("bus.jpg");
  const SegmentedInstance* person = nullptr;
  for (const auto& instance : photo.segmentation.instances) {
    if (instance.class_id == 0 && !instance.mask_is_box) {
      person = &instance;
      break;
    }
  }
  if (person == nullptr) return {};
  const double scale = 300.0 / person->box.height;
  const cv::Size scaled(cvRound(person->box.width * scale), 300);
  cv::Mat crop;
  cv::Mat1b crop_mask;
  cv::resize(photo.image(person->box), crop, scaled, 0, 0, cv::INTER_AREA);
  cv::resize(person->mask(person->box), crop_mask, scaled, 0, 0, cv::INTER_NEAREST);
  PastedPerson out{cv::Mat::zeros(480, 640, CV_8UC3), cv::Mat1b::zeros(480, 640)};
  const cv::Rect where(cv::Point(220, 150), scaled);
  crop.copyTo(out.pixels(where), crop_mask);
  crop_mask.copyTo(out.mask(where));
  return out;
}

cv::Mat composite(const cv::Mat& background, const PastedPerson& person) {
  cv::Mat out = background.clone();
  person.pixels.copyTo(out, person.mask);
  return out;
}

PastedPerson warpPerson(const PastedPerson& person, const cv::Matx23d& warp) {
  PastedPerson out;
  cv::warpAffine(person.pixels, out.pixels, cv::Mat(warp), person.pixels.size(), cv::INTER_LINEAR);
  cv::Mat1b warped_mask;
  cv::warpAffine(person.mask, warped_mask, cv::Mat(warp), person.mask.size(), cv::INTER_NEAREST);
  out.mask = warped_mask;
  return out;
}

double iou(const cv::Mat1b& a, const cv::Mat1b& b) {
  return static_cast<double>(cv::countNonZero(a & b)) / cv::countNonZero(a | b);
}

void orbMatches(const cv::Mat& first, const cv::Mat& second, std::vector<cv::Point2f>& from,
                std::vector<cv::Point2f>& to) {
  const auto orb = cv::ORB::create(1500);
  std::vector<cv::KeyPoint> k1, k2;
  cv::Mat d1, d2;
  orb->detectAndCompute(first, cv::noArray(), k1, d1);
  orb->detectAndCompute(second, cv::noArray(), k2, d2);
  cv::BFMatcher matcher(cv::NORM_HAMMING, /*crossCheck=*/true);
  std::vector<cv::DMatch> matches;
  matcher.match(d1, d2, matches);
  for (const auto& m : matches) {
    if (m.distance > 50) continue;
    from.push_back(k1[static_cast<std::size_t>(m.queryIdx)].pt);
    to.push_back(k2[static_cast<std::size_t>(m.trainIdx)].pt);
  }
}

TEST(MaskTransferData, PastedPersonFollowsItsOwnMotion) {
  EDGESLAM_REQUIRE_SHARED("datasets/7scenes-redkitchen-1000/frame-000000.color.jpg");
  EDGESLAM_REQUIRE_SHARED("datasets/people/bus.jpg");
  EDGESLAM_REQUIRE_SHARED("models");
  const cv::Mat kitchen = cv::imread(
      test::sharedPath("datasets/7scenes-redkitchen-1000/frame-000000.color.jpg").string());
  ASSERT_EQ(kitchen.size(), cv::Size(640, 480));
  const PastedPerson person = personFromBusPhoto();
  ASSERT_FALSE(person.mask.empty()) << "no pixel-masked person found in bus.jpg";

  // The camera pans a little (background), the person walks, turns slightly and comes closer.
  cv::Matx23d background = cv::getRotationMatrix2D(cv::Point2f(320, 240), 1.0, 1.0);
  background(0, 2) += 7;
  background(1, 2) -= 4;
  cv::Matx23d walk = cv::getRotationMatrix2D(cv::Point2f(290, 300), 3.0, 1.06);
  walk(0, 2) += 28;
  walk(1, 2) += 6;

  const cv::Mat keyframe = composite(kitchen, person);
  cv::Mat moved_kitchen;
  cv::warpAffine(kitchen, moved_kitchen, cv::Mat(background), kitchen.size(), cv::INTER_LINEAR,
                 cv::BORDER_REFLECT);
  const PastedPerson moved_person = warpPerson(person, walk);
  const cv::Mat current = composite(moved_kitchen, moved_person);

  std::vector<cv::Point2f> from, to;
  orbMatches(keyframe, current, from, to);
  ASSERT_GT(from.size(), 100u);

  const MaskTransferResult result = transferMask(person.mask, from, to);
  ASSERT_GE(result.instances.size(), 1u);
  const auto& body =
      *std::max_element(result.instances.begin(), result.instances.end(),
                        [](const auto& a, const auto& b) { return a.matches < b.matches; });
  EXPECT_EQ(body.motion, InstanceMotion::kSimilarity);
  const double transferred_iou = iou(result.mask, moved_person.mask);
  const double copied_iou = iou(person.mask, moved_person.mask);  // the paper's plain copy
  EXPECT_GT(transferred_iou, 0.8);
  EXPECT_GT(transferred_iou, copied_iou + 0.1);
  std::printf("[ transfer ] IoU %.3f (plain copy %.3f), %zu matches, %d on the person\n",
              transferred_iou, copied_iou, from.size(), body.matches);

  // Culling with the transferred mask removes the moved person's features, keeps the kitchen's.
  const std::vector<int> kept = indicesOutsideMask(to, result.mask, 4);
  int kept_on_person = 0;
  for (int index : kept)
    kept_on_person += moved_person.mask(to[static_cast<std::size_t>(index)]) != 0;
  EXPECT_LE(kept_on_person, 2);
  EXPECT_GT(kept.size(), from.size() / 2);

  // Cost per 640x480 frame, median of repeated runs.
  SampleStats times;
  for (int i = 0; i < 30; ++i) {
    const Stopwatch stopwatch;
    const MaskTransferResult again = transferMask(person.mask, from, to);
    times.add(stopwatch.elapsedMs());
    ASSERT_EQ(cv::countNonZero(again.mask != result.mask), 0);
  }
  SampleStats label_times;
  const cv::Mat1b labels = person.mask / 255;
  for (int i = 0; i < 30; ++i) {
    const Stopwatch stopwatch;
    const MaskTransferResult again = transferLabels(labels, from, to);
    label_times.add(stopwatch.elapsedMs());
  }
  std::printf(
      "[ transfer ] median per 640x480 frame, %zu matches: %.3f ms from a binary mask, "
      "%.3f ms from a label image\n",
      from.size(), times.summary().median, label_times.summary().median);
  EXPECT_LT(times.summary().median, 20.0);  // ~1 ms expected; generous for a loaded machine
}

}  // namespace
}  // namespace edgeslam
