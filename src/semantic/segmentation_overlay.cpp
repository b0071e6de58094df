#include "semantic/segmentation_overlay.h"

#include <array>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "semantic/bgr_image.h"

namespace edgeslam {
namespace {

cv::Scalar instanceColour(std::size_t index) {
  static const std::array<cv::Scalar, 8> palette = {
      cv::Scalar(60, 60, 230),  cv::Scalar(60, 200, 60),  cv::Scalar(230, 120, 40),
      cv::Scalar(40, 200, 230), cv::Scalar(200, 60, 200), cv::Scalar(200, 200, 40),
      cv::Scalar(120, 60, 230), cv::Scalar(40, 140, 255)};
  return palette[index % palette.size()];
}

}  // namespace

cv::Mat drawSegmentation(const cv::Mat& bgr, const Segmentation& segmentation) {
  cv::Mat canvas = toBgr8(bgr).clone();
  const int thickness = std::max(1, std::max(canvas.cols, canvas.rows) / 500);
  const double font_scale = 0.4 * thickness + 0.1;
  // Same order as the label image: box-only masks under pixel masks, higher scores on top.
  for (const bool pixel_masks : {false, true}) {
    for (std::size_t i = segmentation.instances.size(); i-- > 0;) {
      const SegmentedInstance& instance = segmentation.instances[i];
      if (instance.mask.size() != canvas.size() || instance.mask_is_box == pixel_masks) continue;
      cv::Mat tinted(canvas.size(), canvas.type(), instanceColour(i));
      cv::Mat blended;
      cv::addWeighted(canvas, 0.5, tinted, 0.5, 0.0, blended);
      blended.copyTo(canvas, instance.mask);
    }
  }
  for (std::size_t i = 0; i < segmentation.instances.size(); ++i) {
    const SegmentedInstance& instance = segmentation.instances[i];
    const cv::Scalar colour = instanceColour(i);
    cv::rectangle(canvas, instance.box, colour, thickness);
    char text[96];
    std::snprintf(text, sizeof(text), "%s %.2f", instance.class_name.c_str(), instance.score);
    int baseline = 0;
    const cv::Size text_size =
        cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, font_scale, thickness, &baseline);
    const cv::Point origin(instance.box.x, std::max(text_size.height + 2, instance.box.y - 2));
    cv::rectangle(canvas,
                  cv::Rect(origin.x, origin.y - text_size.height - 2, text_size.width + 2,
                           text_size.height + baseline + 2),
                  colour, cv::FILLED);
    cv::putText(canvas, text, origin + cv::Point(1, 0), cv::FONT_HERSHEY_SIMPLEX, font_scale,
                cv::Scalar(255, 255, 255), thickness, cv::LINE_AA);
  }
  return canvas;
}

}  // namespace edgeslam
