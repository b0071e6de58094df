#pragma once
// CenterNet object detector (MobileNetV3, COCO 80 classes) on OpenCV DNN: class heat-map peaks
// (3x3 local maxima) plus left/top/right/bottom distances on the stride-4 grid, then class-aware
// box NMS.
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <vector>

namespace edgeslam {

struct Detection {
  int class_id = -1;
  float score = 0.0f;
  cv::Rect2f box;  // image pixels, clipped to the image
};

struct CenterNetOptions {
  float score_threshold = 0.3f;
  // For boxes that reach the image's left or right edge. Someone walking into view shows only
  // part of themselves and scores lower (0.15-0.25 where a whole person scores 0.4-0.9), yet
  // they are the ones the mask transfer most needs early.
  float border_score_threshold = 0.2f;
  // For every class but people, wherever the box is (the border's lower threshold is for people
  // walking in). In 100 frames of a kitchen with nothing movable in it the detector saw "cars" at
  // 0.21-0.40 (a toy car, a lunch box), two of them at the border; a real car pasted into that
  // kitchen scores 0.30, so no threshold tells them apart.
  float other_classes_score_threshold = 0.3f;
  float nms_threshold = 0.8f;
  std::vector<int> classes;  // keep only these COCO ids; empty = all 80
  // Side of the square network input, a multiple of 32 (the network is fully convolutional; it
  // was trained at 512). Smaller is faster and still finds people that fill a good part of it.
  int input_size = 512;
};

class CenterNetDetector {
 public:
  // Throws std::runtime_error naming the file when it is missing or not a CenterNet network.
  explicit CenterNetDetector(const std::filesystem::path& model_file);

  std::vector<Detection> detect(const cv::Mat& bgr, const CenterNetOptions& options);

  static constexpr int kDefaultInputSize = 512;
  static constexpr int kStride = 4;

 private:
  cv::dnn::Net net_;
  std::vector<cv::String> output_names_;
};

// Class-aware NMS: within each class, a box overlapping a higher-scoring one by IoU > threshold is
// dropped. Returns the survivors, highest score first.
std::vector<Detection> classAwareNms(std::vector<Detection> detections, float iou_threshold);

}  // namespace edgeslam
