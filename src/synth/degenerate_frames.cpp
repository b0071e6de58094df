#include "synth/degenerate_frames.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>

namespace edgeslam {

cv::Mat rotatedView(const cv::Mat& image, const Eigen::Matrix3d& K,
                    const Eigen::Matrix3d& after_from_before) {
  const Eigen::Matrix3d H = K * after_from_before * K.inverse();
  cv::Mat h(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) h.at<double>(r, c) = H(r, c);
  }
  cv::Mat out;
  cv::warpPerspective(image, out, h, image.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar::all(0));
  return out;
}

Eigen::Matrix3d panRotation(double degrees) {
  return Eigen::AngleAxisd(degrees * std::numbers::pi / 180.0, Eigen::Vector3d::UnitY())
      .toRotationMatrix();
}

cv::Mat overexposed(const cv::Mat& image, double gain) {
  cv::Mat out;
  image.convertTo(out, image.type(), gain);  // saturate_cast clips at 255
  return out;
}

cv::Mat blankLike(const cv::Mat& image, int level) {
  return cv::Mat(image.size(), image.type(), cv::Scalar::all(level));
}

}  // namespace edgeslam
