#include "segment_truth_score.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "io/dataset.h"
#include "synth/ground_truth_masks.h"
#include "synth/mask_metrics.h"
#include "util/timing_stats.h"

namespace edgeslam::cli {
namespace {

cv::Mat shrink(const cv::Mat& image, int reduce) {
  if (reduce <= 1) return image;
  cv::Mat out;
  cv::resize(image, out,
             cv::Size((image.cols + reduce - 1) / reduce, (image.rows + reduce - 1) / reduce), 0, 0,
             cv::INTER_AREA);
  return out;
}

// The segmentation's movable pixels at the truth's size.
cv::Mat1b movableMask(const Segmentation& segmentation, cv::Size size) {
  cv::Mat1b mask = segmentation.label_image > 0;
  if (mask.size() != size) cv::resize(mask, mask, size, 0, 0, cv::INTER_NEAREST);
  return mask;
}

}  // namespace

void scoreSegmenterOnSequence(Segmenter& segmenter, const std::filesystem::path& dataset_dir,
                              const TruthScoreOptions& options) {
  const auto truth = GroundTruthMasks::open(dataset_dir);
  if (!truth) {
    throw std::invalid_argument(
        fmt::format("--truth {}: no {} (not a sequence made by `edgeslam synth-dynamic`)",
                    dataset_dir.string(), GroundTruthMasks::kListFile));
  }
  const auto dataset = openDataset(dataset_dir);
  const std::size_t frames = std::min(dataset->info().frame_count, truth->size());
  const std::size_t step = static_cast<std::size_t>(std::max(1, options.every));
  SampleStats iou;
  SampleStats times;
  std::size_t missed = 0;
  std::size_t false_alarms = 0;
  std::size_t scored = 0;
  for (std::size_t index = 0; index < frames; index += step) {
    const DatasetFrame frame = dataset->load(index);
    const cv::Mat1b expected = truth->load(index);
    const cv::Mat image = shrink(frame.color.empty() ? frame.gray : frame.color, options.reduce);
    const Segmentation segmentation = segmenter.segment(image);
    times.add(segmentation.elapsed_ms);
    const cv::Mat1b predicted = movableMask(segmentation, expected.size());
    const bool truth_has_people = cv::countNonZero(expected) > 0;
    const bool predicted_any = cv::countNonZero(predicted) > 0;
    if (truth_has_people && !predicted_any) ++missed;
    if (!truth_has_people && predicted_any) ++false_alarms;
    const auto value = maskIoU(predicted, expected);
    ++scored;
    if (value) iou.add(*value);
    fmt::print("frame {:4d}: {} instances, truth covers {:5.1f} %, IoU {}\n", index,
               segmentation.instances.size(), 100.0 * cv::countNonZero(expected) / expected.total(),
               value ? fmt::format("{:.3f}", *value) : std::string("-"));
  }
  if (iou.count() == 0) {
    fmt::print("no frame with people in the truth or the prediction among {} scored\n", scored);
    return;
  }
  const auto summary = iou.summary();
  fmt::print(
      "segmenter vs truth on {} frames ({} with people in either): IoU median {:.3f} "
      "[p25 {:.3f}, p75 {:.3f}], people missed on {} frames, false alarms on {}, {:.1f} ms per "
      "frame (median)\n",
      scored, iou.count(), summary.median, percentile(iou.samples(), 0.25),
      percentile(iou.samples(), 0.75), missed, false_alarms, times.summary().median);
}

}  // namespace edgeslam::cli
