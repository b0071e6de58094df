// Points observed on a movable object in a segmented keyframe leave the map; points just outside
// its outline stay.
#include "mapping/movable_points.h"

#include <gtest/gtest.h>

#include "map/keyframe.h"
#include "map/map_point.h"

namespace edgeslam {
namespace {

TEST(MovablePoints, ErasesThePointsSeenInsideTheMaskOnly) {
  auto features = std::make_shared<FrameFeatures>();
  // Inside the object, on its edge, just outside, far away.
  for (const cv::Point2f p : {cv::Point2f(150, 150), cv::Point2f(100.5f, 150), cv::Point2f(97, 150),
                              cv::Point2f(400, 300)}) {
    features->keypoints.emplace_back(p, 31.f);
  }
  features->descriptors = cv::Mat::zeros(4, 32, CV_8U);
  Map map;
  MutexLock lock(map.updateMutex());
  KeyFrame* keyframe = map.createKeyFrame(0, 0.0, features, SE3d());
  std::vector<MapPoint*> points;
  for (std::size_t i = 0; i < 4; ++i) {
    points.push_back(map.createMapPoint(Eigen::Vector3d(0, 0, 2.0 + i), keyframe));
    map.addObservation(points.back(), keyframe, i);
  }
  cv::Mat1b labels = cv::Mat1b::zeros(480, 640);
  labels(cv::Rect(100, 100, 100, 100)).setTo(3);
  map.takeChanges();
  const std::size_t erased = eraseMovablePoints(map, *keyframe, labels, 2);
  EXPECT_EQ(erased, 1u);  // the edge point is within the 2 px erosion
  EXPECT_TRUE(points[0]->isBad());
  EXPECT_FALSE(points[1]->isBad());
  EXPECT_FALSE(points[2]->isBad());
  EXPECT_FALSE(points[3]->isBad());
  EXPECT_EQ(map.pointCount(), 3u);
  EXPECT_EQ(map.changes().points_erased.size(), 1u);  // goes out with the next slice
  // Without erosion the edge point goes too; an empty mask erases nothing.
  EXPECT_EQ(eraseMovablePoints(map, *keyframe, labels, 0), 1u);
  EXPECT_EQ(eraseMovablePoints(map, *keyframe, cv::Mat1b::zeros(480, 640)), 0u);
}

}  // namespace
}  // namespace edgeslam
