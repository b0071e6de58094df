#pragma once
// The mobile view's camera image: the frame with its features drawn by state and the semantic
// mask overlaid, as a JPEG for /api/frame.jpg.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace edgeslam::viz {

struct FrameImage {
  cv::Mat image;                    // grey or BGR, the frame as the camera gave it
  std::vector<cv::Point2f> on_map;  // features tracking matched to a map point
  std::vector<cv::Point2f> fresh;   // features tracking saw that no map point has (yet)
  std::vector<cv::Point2f> culled;  // features dropped as on a movable (dynamic) object
  cv::Mat1b mask;                   // movable-object mask (non-zero), empty when there is none
};

// Colours (BGR) of the feature states: green rings on the map, small blue dots new, red crosses
// culled; the mask is tinted magenta.
inline const cv::Scalar kOnMapColour{122, 224, 62};
inline const cv::Scalar kFreshColour{255, 160, 40};
inline const cv::Scalar kCulledColour{77, 77, 255};

// The frame in BGR, scaled down to at most `max_width` pixels wide, with the features drawn.
cv::Mat renderFrame(const FrameImage& frame, int max_width = 480);
// renderFrame as JPEG bytes.
std::string renderFrameJpeg(const FrameImage& frame, int max_width = 480, int quality = 75);

}  // namespace edgeslam::viz
