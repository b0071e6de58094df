#pragma once
// Keypoint orientation by intensity centroid (Rosin; as used by ORB): the angle of the vector from
// the keypoint to the intensity-weighted centroid of a circular patch around it.
#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace edgeslam {

class IntensityCentroid {
 public:
  // Throws std::invalid_argument when radius < 1.
  explicit IntensityCentroid(int radius = 15);

  int radius() const { return radius_; }
  // Angle in degrees, in [0, 360), measured in image coordinates (x right, y down). The keypoint
  // must be at least radius() pixels from every border of `image` (CV_8UC1); this is the caller's
  // contract, checked by compute() below.
  float angleAt(const cv::Mat& image, cv::Point2f point) const;
  // Sets kp.angle for every keypoint; throws std::invalid_argument for a keypoint too close to the
  // border.
  void compute(const cv::Mat& image, std::span<cv::KeyPoint> keypoints) const;

 private:
  int radius_;
  std::vector<int> half_width_;  // half width of the patch's row at vertical offset v >= 0
};

}  // namespace edgeslam
