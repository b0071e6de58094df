#include "synth/people_compositor.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

const cv::Size kImageSize(320, 240);

// An upright ellipse "person" of one colour, 200 x 80 px.
PersonSprite ellipseSprite(cv::Vec3b color) {
  PersonSprite sprite;
  sprite.color = cv::Mat3b(200, 80, color);
  cv::Mat1b silhouette = cv::Mat1b::zeros(200, 80);
  cv::ellipse(silhouette, cv::Point(40, 100), cv::Size(38, 98), 0, 0, 360, 255, cv::FILLED);
  silhouette.convertTo(sprite.silhouette, CV_32F, 1.0 / 255.0);
  return sprite;
}

PersonPlacement placeAt(std::size_t sprite, double center_x, double foot_y, double height,
                        double depth) {
  PersonPlacement placement;
  placement.sprite = sprite;
  placement.center_x = center_x;
  placement.foot_y = foot_y;
  placement.height_px = height;
  placement.depth_m = depth;
  return placement;
}

cv::Mat3b noiseImage() {
  cv::Mat3b image(kImageSize);
  cv::randu(image, 0, 255);
  return image;
}

TEST(PeopleCompositor, MaskIsAlphaAboveHalfAndPixelsChangeOnlyNearIt) {
  const std::vector<PersonSprite> sprites{ellipseSprite({0, 0, 255})};
  const cv::Mat3b image = noiseImage();
  const CompositeFrame frame =
      compositePeople(image, cv::Mat(), kImageSize, {placeAt(0, 160, 220, 100, 3.0)}, sprites);
  EXPECT_EQ(cv::countNonZero(frame.mask != ((frame.alpha > 0.5f) & 255)), 0);
  // The ellipse (semi-axes 38 x 98 in 80 x 200) scaled by 0.5: area pi * 19 * 49.
  EXPECT_NEAR(cv::countNonZero(frame.mask), 3.14159 * 19 * 49, 100);
  EXPECT_NEAR(frame.coverage, cv::countNonZero(frame.mask) / double(kImageSize.area()), 1e-12);
  const cv::Rect body = cv::boundingRect(frame.mask);
  EXPECT_NEAR(body.x + body.width / 2.0, 160, 2);
  EXPECT_NEAR(body.br().y, 220, 2);
  EXPECT_NEAR(body.height, 100, 3);

  cv::Mat1b near_person;
  cv::dilate(frame.mask, near_person, cv::Mat1b::ones(7, 7));
  cv::Mat diff;
  cv::absdiff(frame.image, image, diff);
  cv::Mat1b changed_any;
  cv::transform(diff, changed_any, cv::Matx13f(1, 1, 1));
  changed_any = changed_any > 0;
  EXPECT_EQ(cv::countNonZero(changed_any & ~near_person), 0);
  cv::Mat1b core;
  cv::erode(frame.mask, core, cv::Mat1b::ones(7, 7));
  ASSERT_GT(cv::countNonZero(core), 1000);
  for (int y = 0; y < core.rows; ++y) {
    for (int x = 0; x < core.cols; ++x) {
      if (core(y, x)) {
        ASSERT_EQ(cv::Vec3b(frame.image.at<cv::Vec3b>(y, x)), cv::Vec3b(0, 0, 255));
      }
    }
  }
}

TEST(PeopleCompositor, GreyImagesGetTheGreySprite) {
  const std::vector<PersonSprite> sprites{ellipseSprite({0, 0, 255})};
  const cv::Mat1b image(kImageSize, 10);
  const CompositeFrame frame =
      compositePeople(image, cv::Mat(), kImageSize, {placeAt(0, 100, 200, 120, 2.0)}, sprites);
  ASSERT_EQ(frame.image.type(), CV_8UC1);
  cv::Mat1b core;
  cv::erode(frame.mask, core, cv::Mat1b::ones(7, 7));
  const cv::Point inside = cv::boundingRect(core).tl() + cv::Point(20, 60);
  ASSERT_TRUE(core(inside));
  EXPECT_NEAR(frame.image.at<uchar>(inside), 76, 1);  // grey of pure red (BT.601)
  EXPECT_EQ(frame.image.at<uchar>(5, 5), 10);
}

TEST(PeopleCompositor, PeopleAreNeverBehindTheSceneAndNearerOnesCoverFartherOnes) {
  const std::vector<PersonSprite> sprites{ellipseSprite({0, 0, 255}), ellipseSprite({255, 0, 0})};
  cv::Mat1f depth(kImageSize, 3.0f);
  depth(cv::Rect(0, 0, 150, 240)).setTo(1.0f);    // a wall close by on the left
  depth(cv::Rect(200, 0, 120, 240)).setTo(0.0f);  // no depth on the right
  // Red at 2 m nominal, partly over the 1 m wall; blue at 1.5 m nominal, in front of it.
  const std::vector<PersonPlacement> placements{placeAt(0, 160, 220, 100, 2.0),
                                                placeAt(1, 180, 230, 150, 1.5)};
  const CompositeFrame frame =
      compositePeople(noiseImage(), depth, kImageSize, placements, sprites);
  ASSERT_EQ(frame.depth_m.size(), kImageSize);
  for (int y = 0; y < depth.rows; ++y) {
    for (int x = 0; x < depth.cols; ++x) {
      if (!frame.mask(y, x)) {
        ASSERT_FLOAT_EQ(frame.depth_m(y, x), depth(y, x)) << x << "," << y;
        continue;
      }
      ASSERT_GT(frame.depth_m(y, x), 0.0f);
      if (depth(y, x) > 0.0f) {
        ASSERT_LT(frame.depth_m(y, x), depth(y, x)) << x << "," << y;
      }
    }
  }
  const cv::Point red_only(150, 200), overlap(170, 170), blue_valid(185, 120),
      blue_no_depth(205, 150);
  for (const cv::Point& p : {red_only, overlap, blue_valid, blue_no_depth})
    ASSERT_TRUE(frame.mask(p));
  // The red person covers the wall, so it stands in front of it: 1 m - 0.1 m clearance.
  EXPECT_NEAR(frame.depth_m(red_only), 0.9f, 1e-5);
  // The nearer (blue) person is drawn over the red one and stays in front of it there.
  EXPECT_EQ(cv::Vec3b(frame.image.at<cv::Vec3b>(overlap)), cv::Vec3b(255, 0, 0));
  EXPECT_LT(frame.depth_m(overlap), 0.9f);
  EXPECT_NEAR(frame.depth_m(blue_valid), 1.5f, 1e-5);
  EXPECT_NEAR(frame.depth_m(blue_no_depth), 1.5f, 1e-5);
}

TEST(PeopleCompositor, NominalDepthMovesInFrontOfACloseSurface) {
  const std::vector<PersonSprite> sprites{ellipseSprite({0, 0, 255})};
  const cv::Mat1f depth(kImageSize, 1.2f);
  const CompositeFrame frame =
      compositePeople(cv::Mat(), depth, kImageSize, {placeAt(0, 160, 220, 100, 4.0)}, sprites);
  EXPECT_TRUE(frame.image.empty());
  cv::Mat1b core;
  cv::erode(frame.mask, core, cv::Mat1b::ones(3, 3));
  double low = 0, high = 0;
  cv::minMaxLoc(frame.depth_m, &low, &high, nullptr, nullptr, core);
  EXPECT_NEAR(low, 1.1, 1e-5);  // 10th percentile 1.2 m - 0.1 m clearance
  EXPECT_NEAR(high, 1.1, 1e-5);
}

TEST(PeopleCompositor, MirroredPlacementFlipsTheSprite) {
  PersonSprite sprite = ellipseSprite({0, 0, 255});
  sprite.color(cv::Rect(0, 0, 40, 200)).setTo(cv::Vec3b(0, 255, 0));  // left half green
  const std::vector<PersonSprite> sprites{sprite};
  PersonPlacement placement = placeAt(0, 160, 220, 200, 2.0);
  const cv::Mat3b image(kImageSize, cv::Vec3b(0, 0, 0));
  const CompositeFrame plain = compositePeople(image, cv::Mat(), kImageSize, {placement}, sprites);
  placement.mirrored = true;
  const CompositeFrame flipped =
      compositePeople(image, cv::Mat(), kImageSize, {placement}, sprites);
  EXPECT_EQ(cv::Vec3b(plain.image.at<cv::Vec3b>(120, 150)), cv::Vec3b(0, 255, 0));
  EXPECT_EQ(cv::Vec3b(flipped.image.at<cv::Vec3b>(120, 150)), cv::Vec3b(0, 0, 255));
}

TEST(PeopleCompositor, RejectsBadInput) {
  const std::vector<PersonSprite> sprites{ellipseSprite({0, 0, 255})};
  const auto placement = placeAt(0, 160, 220, 100, 2.0);
  EXPECT_THROW(
      compositePeople(cv::Mat(kImageSize, CV_32FC3), cv::Mat(), kImageSize, {placement}, sprites),
      std::invalid_argument);
  EXPECT_THROW(compositePeople(cv::Mat3b(10, 10), cv::Mat(), kImageSize, {placement}, sprites),
               std::invalid_argument);
  EXPECT_THROW(compositePeople(cv::Mat(), cv::Mat1w(kImageSize), kImageSize, {placement}, sprites),
               std::invalid_argument);
  EXPECT_THROW(
      compositePeople(cv::Mat(), cv::Mat(), kImageSize, {placeAt(3, 1, 1, 10, 1)}, sprites),
      std::out_of_range);
}

}  // namespace
}  // namespace edgeslam
