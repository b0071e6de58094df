#pragma once
// Real frames made degenerate for tests of initialisation and tracking: the same view again (a
// camera that does not move), the view after a pure rotation of the camera (no parallax), a blank
// frame and an overexposed one. Everything stays a real image, so features and matching see what
// they would see from a real camera in that situation.
#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace edgeslam {

// What a camera with calibration K sees after rotating by R (camera-after-from-camera-before)
// about its centre: the image warped by K R K^-1. Parts of the new view the old one never saw are
// black.
cv::Mat rotatedView(const cv::Mat& image, const Eigen::Matrix3d& K,
                    const Eigen::Matrix3d& after_from_before);

// Rotation about the camera's y axis (pan) by `degrees`.
Eigen::Matrix3d panRotation(double degrees);

// The image scaled by `gain` and clipped: gain 6 leaves a real indoor frame mostly white.
cv::Mat overexposed(const cv::Mat& image, double gain);

// A uniform frame of the same size and type (a lens cap, a dropped exposure).
cv::Mat blankLike(const cv::Mat& image, int level);

}  // namespace edgeslam
