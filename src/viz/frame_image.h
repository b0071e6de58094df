#pragma once
// The mobile view's camera image: the frame with its features drawn by state and the semantic
// mask overlaid, as a JPEG for /api/frame.jpg.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace edgeslam::viz {

struct FrameImage {
  cv::Mat image;                    // grey or BGR, the frame as the camera gave it
  std::vector<cv::Point2f> kept;    // features tracking used
  std::vector<cv::Point2f> culled;  // features dropped as on a movable (dynamic) object
  cv::Mat1b mask;                   // movable-object mask (non-zero), empty when there is none
};

// Scaled down to at most `max_width` pixels wide; JPEG bytes.
std::string renderFrameJpeg(const FrameImage& frame, int max_width = 480, int quality = 75);

}  // namespace edgeslam::viz
