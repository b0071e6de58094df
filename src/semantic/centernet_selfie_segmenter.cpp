#include "semantic/centernet_selfie_segmenter.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "semantic/bgr_image.h"
#include "semantic/coco_classes.h"
#include "util/timing_stats.h"

namespace edgeslam {
namespace {

std::filesystem::path modelPath(const SegmenterOptions& options,
                                const std::filesystem::path& explicit_path, const char* file) {
  return explicit_path.empty() ? options.model_dir / file : explicit_path;
}

void checkThreshold(float value, const char* name) {
  if (!(value >= 0.0f && value <= 1.0f)) {
    throw std::invalid_argument(std::string(name) + " must be in [0, 1], got " +
                                std::to_string(value));
  }
}

cv::Rect toPixels(const cv::Rect2f& box, cv::Size size) {
  const cv::Point top_left(cvFloor(box.x), cvFloor(box.y));
  const cv::Point bottom_right(cvCeil(box.x + box.width), cvCeil(box.y + box.height));
  return cv::Rect(top_left, bottom_right) & cv::Rect(cv::Point(), size);
}

}  // namespace

CenterNetSelfieSegmenter::CenterNetSelfieSegmenter(const SegmenterOptions& options)
    : options_(options),
      detector_(modelPath(options, options.detector_model, kDetectorFile)),
      person_masks_(modelPath(options, options.person_mask_model, kPersonMaskFile)) {
  checkThreshold(options.mask_threshold, "mask threshold");
  checkThreshold(options.min_mask_coverage, "minimum mask coverage");
  if (!(options.crop_padding >= 0.0f && options.crop_padding <= 2.0f)) {
    throw std::invalid_argument("crop padding must be in [0, 2], got " +
                                std::to_string(options.crop_padding));
  }
  setNmsThreshold(options.nms_threshold);
  setScoreThreshold(options.score_threshold);
  checkThreshold(options.border_score_threshold, "border score threshold");
  detector_options_.border_score_threshold = options.border_score_threshold;
  checkThreshold(options.other_classes_score_threshold, "score threshold of other classes");
  detector_options_.other_classes_score_threshold = options.other_classes_score_threshold;
  detector_options_.classes = options.classes.empty() ? defaultMovableClasses() : options.classes;
  if (options.detector_input_size < 64 || options.detector_input_size % 32 != 0) {
    throw std::invalid_argument("detector input size must be a multiple of 32 from 64, got " +
                                std::to_string(options.detector_input_size));
  }
  detector_options_.input_size = options.detector_input_size;
  for (int id : detector_options_.classes) cocoClassName(id);  // throws for a bad id
  warmUp();
}

void CenterNetSelfieSegmenter::warmUp() {
  // OpenCV DNN sets each network up on its first forward pass (a few times a later pass): here,
  // before the first keyframe, rather than on it, where it made the first mask of a run ~4x later.
  const cv::Mat blank(options_.detector_input_size, options_.detector_input_size, CV_8UC3,
                      cv::Scalar::all(0));
  detector_.detect(blank, detector_options_);
  person_masks_.probability(blank, cv::Rect(0, 0, blank.cols, blank.rows));
}

void CenterNetSelfieSegmenter::setNmsThreshold(float nm) {
  checkThreshold(nm, "NMS threshold");
  detector_options_.nms_threshold = nm;
}

void CenterNetSelfieSegmenter::setScoreThreshold(float score) {
  checkThreshold(score, "score threshold");
  detector_options_.score_threshold = score;
}

Segmentation CenterNetSelfieSegmenter::segment(const cv::Mat& image) {
  const Stopwatch stopwatch;
  const cv::Mat bgr = toBgr8(image);
  const std::vector<Detection> detections = detector_.detect(bgr, detector_options_);
  std::vector<SegmentedInstance> instances;
  instances.reserve(detections.size());
  for (const Detection& detection : detections) {
    SegmentedInstance instance = maskInstance(bgr, detection);
    if (!instance.box.empty()) instances.push_back(std::move(instance));
  }
  Segmentation result = assembleSegmentation(std::move(instances), bgr.size());
  result.elapsed_ms = stopwatch.elapsedMs();
  return result;
}

SegmentedInstance CenterNetSelfieSegmenter::maskInstance(const cv::Mat& bgr,
                                                         const Detection& detection) {
  SegmentedInstance instance;
  instance.class_id = detection.class_id;
  instance.class_name = cocoClassName(detection.class_id);
  instance.score = detection.score;
  instance.box = toPixels(detection.box, bgr.size());
  instance.mask = cv::Mat1b::zeros(bgr.size());
  if (instance.box.empty()) return instance;
  instance.mask(instance.box).setTo(255);
  instance.mask_is_box = true;
  if (detection.class_id != kCocoPerson) return instance;

  const float pad = options_.crop_padding;
  const cv::Rect2f padded(
      detection.box.x - pad * detection.box.width, detection.box.y - pad * detection.box.height,
      detection.box.width * (1.0f + 2.0f * pad), detection.box.height * (1.0f + 2.0f * pad));
  const cv::Rect crop = toPixels(padded, bgr.size());
  const cv::Mat1f probability = person_masks_.probability(bgr, crop);
  // Keep the mask inside the person's own box, so that neighbours in the padding are not taken.
  const cv::Rect box_in_crop = instance.box - crop.tl();
  cv::Mat1b person = probability(box_in_crop) > options_.mask_threshold;
  const double coverage = static_cast<double>(cv::countNonZero(person)) / instance.box.area();
  if (coverage < options_.min_mask_coverage) return instance;
  instance.mask(instance.box).setTo(0);
  person.copyTo(instance.mask(instance.box));
  instance.mask_is_box = false;
  return instance;
}

}  // namespace edgeslam
