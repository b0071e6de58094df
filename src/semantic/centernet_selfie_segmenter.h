#pragma once
// Backend "centernet-selfie": CenterNet finds the movable objects; each person box gets a
// pixel mask from the selfie model on a padded crop, every other movable object is masked by its
// box. Where the person mask covers too little of its box (people cut by the border, back views the
// selfie model misses), the whole box is masked: missing a person costs SLAM more than losing a
// few background features.
#include <memory>

#include "semantic/centernet_detector.h"
#include "semantic/person_mask_model.h"
#include "semantic/segmenter.h"

namespace edgeslam {

class CenterNetSelfieSegmenter final : public Segmenter {
 public:
  explicit CenterNetSelfieSegmenter(const SegmenterOptions& options);

  Segmentation segment(const cv::Mat& bgr) override;
  void setNmsThreshold(float nm) override;
  float nmsThreshold() const override { return detector_options_.nms_threshold; }
  void setScoreThreshold(float score) override;
  float scoreThreshold() const override { return detector_options_.score_threshold; }
  std::string backendName() const override { return "centernet-selfie"; }

  static constexpr const char* kDetectorFile = "centernet_mbv3_coco_512.onnx";
  static constexpr const char* kPersonMaskFile = "mediapipe_selfie_256.onnx";

 private:
  void warmUp();
  SegmentedInstance maskInstance(const cv::Mat& bgr, const Detection& detection);

  SegmenterOptions options_;
  CenterNetOptions detector_options_;
  CenterNetDetector detector_;
  PersonMaskModel person_masks_;
};

}  // namespace edgeslam
