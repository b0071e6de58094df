#pragma once
// Instance segmentation of movable objects behind one interface, so that backends (the OpenCV-DNN
// CenterNet + selfie pair today; Mask R-CNN or YOLO-seg where weights exist) are interchangeable.
// A Segmenter is not thread-safe: use one per thread.
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "semantic/segmentation.h"

namespace edgeslam {

// `models/` under EDGESLAM_SHARED when that is set, else under the build's default shared folder
// (CMake cache EDGESLAM_SHARED_DIR, normally ../shared beside the source tree).
std::filesystem::path defaultModelDirectory();

struct SegmenterOptions {
  std::string backend = "centernet-selfie";
  std::filesystem::path model_dir = defaultModelDirectory();
  // Empty: the backend's default file name inside model_dir.
  std::filesystem::path detector_model;
  std::filesystem::path person_mask_model;
  float score_threshold = 0.3f;  // detections below are dropped
  // The same for detections whose box reaches the image's edge (people walking into view score
  // lower while only part of them shows).
  float border_score_threshold = 0.2f;
  // Classes other than people, wherever their box is (the border threshold is for people).
  float other_classes_score_threshold = 0.3f;
  float nms_threshold = 0.8f;      // box IoU above which the weaker same-class box is dropped (nm)
  std::vector<int> classes;        // COCO ids to segment; empty = defaultMovableClasses()
  float mask_threshold = 0.5f;     // person probability above which a pixel is in the mask
  float min_mask_coverage = 0.2f;  // person masks covering less of their box fall back to the box
  float crop_padding = 0.15f;      // context added around a person box before masking, per side
  // Side of the detector's square input (multiple of 32). The network was trained at 512;
  // keyframes arrive at half resolution (320x240 for VGA), where 320 loses little and costs
  // 40 % of 512.
  int detector_input_size = 512;
};

class Segmenter {
 public:
  virtual ~Segmenter() = default;
  // `bgr` is an 8-bit 3-channel (or 1-channel grey) image of any size.
  virtual Segmentation segment(const cv::Mat& bgr) = 0;
  virtual void setNmsThreshold(float nm) = 0;
  virtual float nmsThreshold() const = 0;
  virtual void setScoreThreshold(float score) = 0;
  virtual float scoreThreshold() const = 0;
  virtual std::string backendName() const = 0;
};

// Names accepted by SegmenterOptions::backend.
std::vector<std::string> segmenterBackends();

// Throws std::invalid_argument for an unknown backend or out-of-range thresholds, and
// std::runtime_error naming the file when a model is missing or cannot be parsed.
std::unique_ptr<Segmenter> makeSegmenter(const SegmenterOptions& options);

}  // namespace edgeslam
