#include "semantic_evaluation.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <opencv2/core.hpp>

#include "synth/mask_metrics.h"

namespace edgeslam::cli {
namespace {

std::vector<cv::Point2f> positions(const FrameFeatures& features) {
  std::vector<cv::Point2f> out;
  out.reserve(features.size());
  for (const cv::KeyPoint& kp : features.keypoints) out.push_back(kp.pt);
  return out;
}

}  // namespace

std::optional<SemanticEvaluation> SemanticEvaluation::open(
    const std::filesystem::path& dataset_dir) {
  std::optional<GroundTruthMasks> masks = GroundTruthMasks::open(dataset_dir);
  if (!masks) return std::nullopt;
  return SemanticEvaluation(std::move(*masks));
}

void SemanticEvaluation::addFrame(std::size_t index, const TrackResult& result,
                                  const SemanticFrame* frame) {
  if (frame == nullptr || frame->all == nullptr || index >= masks_.size()) return;
  const cv::Mat1b truth = masks_.load(index);
  if (!frame->mask.empty()) {
    const auto iou = maskIoU(frame->mask, truth);
    if (iou && result.new_keyframe) iou_keyframes_.add(*iou);
    if (iou && !result.new_keyframe) {
      iou_.add(*iou);
      if (spdlog::should_log(spdlog::level::debug)) {
        spdlog::debug(
            "frame {}: mask of keyframe frame {} has IoU {:.3f} ({} px masked, {} px of "
            "people, {} px both)",
            index, frame->mask_source_frame.value_or(0), *iou, cv::countNonZero(frame->mask),
            cv::countNonZero(truth), cv::countNonZero(frame->mask & truth));
      }
    }
  }
  features_on_people_ += countFeaturesOnMask(positions(*frame->all), truth).on_mask;
  features_on_people_kept_ += countFeaturesOnMask(positions(*frame->kept), truth).on_mask;
  features_culled_ += frame->all->size() - frame->kept->size();
}

nlohmann::json SemanticEvaluation::json() const {
  nlohmann::json out;
  out["mask_iou_median"] =
      iou_.count() > 0 ? nlohmann::json(iou_.summary().median) : nlohmann::json(nullptr);
  out["mask_iou_frames"] = iou_.count();
  out["mask_iou_keyframes_median"] = iou_keyframes_.count() > 0
                                         ? nlohmann::json(iou_keyframes_.summary().median)
                                         : nlohmann::json(nullptr);
  out["mask_iou_keyframes_frames"] = iou_keyframes_.count();
  const std::size_t culled_on_people = features_on_people_ - features_on_people_kept_;
  out["culled_precision"] = features_culled_ > 0
                                ? nlohmann::json(static_cast<double>(culled_on_people) /
                                                 static_cast<double>(features_culled_))
                                : nlohmann::json(nullptr);
  out["culled_recall"] = features_on_people_ > 0
                             ? nlohmann::json(static_cast<double>(culled_on_people) /
                                              static_cast<double>(features_on_people_))
                             : nlohmann::json(nullptr);
  out["dynamic_features"] = features_on_people_;
  out["dynamic_features_kept_ratio"] =
      features_on_people_ > 0 ? nlohmann::json(static_cast<double>(features_on_people_kept_) /
                                               static_cast<double>(features_on_people_))
                              : nlohmann::json(nullptr);
  return out;
}

std::string SemanticEvaluation::summaryLine() const {
  const double kept = features_on_people_ > 0 ? static_cast<double>(features_on_people_kept_) /
                                                    static_cast<double>(features_on_people_)
                                              : 0.0;
  return fmt::format(
      "masks        transferred-mask IoU median {:.3f} over {} non-keyframes; {} of {} features "
      "on people kept ({:.1f} %)",
      iou_.count() > 0 ? iou_.summary().median : 0.0, iou_.count(), features_on_people_kept_,
      features_on_people_, 100.0 * kept);
}

}  // namespace edgeslam::cli
