#pragma once
// Scores the semantic culling of a run on a generated dynamic sequence (one with ground-truth
// masks): transferred-mask IoU on non-keyframes, and the share of the features on people that
// tracking still got.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "client/tracking_types.h"
#include "modes/slam_system.h"
#include "synth/ground_truth_masks.h"
#include "util/timing_stats.h"

namespace edgeslam::cli {

class SemanticEvaluation {
 public:
  // nullopt when the dataset folder has no ground-truth masks.
  static std::optional<SemanticEvaluation> open(const std::filesystem::path& dataset_dir);

  // After frame `index` was processed; `frame` may be nullptr (offload mode: nothing to score).
  void addFrame(std::size_t index, const TrackResult& result, const SemanticFrame* frame);

  // mask_iou_median (non-keyframes; null without any scored frame), mask_iou_frames,
  // mask_iou_keyframes_median / _frames (keyframes, with the mask they were tracked with),
  // dynamic_features_kept_ratio (null without any feature on people), dynamic_features,
  // culled_precision (culled features that were on people) and culled_recall (features on people
  // that were culled), null where nothing was culled / on people.
  nlohmann::json json() const;
  std::string summaryLine() const;

 private:
  explicit SemanticEvaluation(GroundTruthMasks masks) : masks_(std::move(masks)) {}

  GroundTruthMasks masks_;
  SampleStats iou_;
  SampleStats iou_keyframes_;
  std::size_t features_on_people_ = 0;
  std::size_t features_on_people_kept_ = 0;
  std::size_t features_culled_ = 0;
};

}  // namespace edgeslam::cli
