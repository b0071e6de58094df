#include "features/keypoint_undistortion.h"

namespace edgeslam {

std::vector<cv::KeyPoint> undistortKeypoints(const PinholeCamera& camera,
                                             const std::vector<cv::KeyPoint>& keypoints) {
  std::vector<cv::KeyPoint> undistorted = keypoints;
  if (!camera.hasDistortion() || keypoints.empty()) return undistorted;
  std::vector<cv::Point2f> points;
  points.reserve(keypoints.size());
  for (const cv::KeyPoint& kp : keypoints) points.push_back(kp.pt);
  const std::vector<cv::Point2f> moved = camera.undistort(points);
  for (std::size_t i = 0; i < undistorted.size(); ++i) undistorted[i].pt = moved[i];
  return undistorted;
}

}  // namespace edgeslam
