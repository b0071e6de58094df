#include "semantic/transfer_matching.h"

#include <array>
#include <climits>

#include "features/descriptor_distance.h"

namespace edgeslam {
namespace {

struct Candidate {
  int reference = -1;
  int distance = INT_MAX;
};

std::uint8_t labelAt(const cv::Mat1b& labels, const cv::Point2f& p) {
  const int x = cvFloor(p.x), y = cvFloor(p.y);
  if (x < 0 || y < 0 || x >= labels.cols || y >= labels.rows) return 0;
  return labels(y, x);
}

}  // namespace

TransferMatches matchForTransfer(const FrameFeatures& reference, const cv::Mat1b& labels_near,
                                 const FrameFeatures& current, const MotionPrediction& predict,
                                 float search_radius_px, const TransferMatchOptions& options) {
  return matchForTransfer(
      reference, labels_near, current, predict,
      [search_radius_px](std::uint8_t) { return search_radius_px; }, options);
}

TransferMatches matchForTransfer(const FrameFeatures& reference, const cv::Mat1b& labels_near,
                                 const FrameFeatures& current, const MotionPrediction& predict,
                                 const SearchRadius& radius, const TransferMatchOptions& options) {
  std::array<float, 256> radius_of{};
  for (std::size_t label = 0; label < radius_of.size(); ++label) {
    radius_of[label] = radius(static_cast<std::uint8_t>(label));
  }
  std::vector<Candidate> best_for_current(current.size());
  std::vector<int> in_area;
  std::vector<std::uint8_t> label_of(reference.size(), 0);
  int background_seen = 0;
  for (std::size_t r = 0; r < reference.size(); ++r) {
    const cv::KeyPoint& kp = reference.keypoints[r];
    const std::uint8_t label = labelAt(labels_near, kp.pt);
    if (label == 0 && (background_seen++ % std::max(1, options.background_stride)) != 0) continue;
    label_of[r] = label;
    const cv::Point2f predicted = predict(label, kp.pt);
    const int min_level = std::max(0, kp.octave - options.level_window);
    const int max_level = kp.octave + options.level_window;
    current.grid.featuresInArea(predicted.x, predicted.y, radius_of[label], min_level, max_level,
                                in_area);
    const std::uint8_t* descriptor = reference.descriptors.ptr<std::uint8_t>(static_cast<int>(r));
    int best = INT_MAX, second = INT_MAX, best_index = -1;
    for (const int c : in_area) {
      const int d = descriptorDistance(descriptor, current.descriptors.ptr<std::uint8_t>(c));
      if (d < best) {
        second = best;
        best = d;
        best_index = c;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_index < 0 || best > options.max_descriptor_distance) continue;
    if (second != INT_MAX && static_cast<float>(best) > options.ratio * static_cast<float>(second))
      continue;
    Candidate& slot = best_for_current[best_index];
    if (best < slot.distance) slot = {static_cast<int>(r), best};
  }
  TransferMatches matches;
  for (std::size_t c = 0; c < best_for_current.size(); ++c) {
    const Candidate& slot = best_for_current[c];
    if (slot.reference < 0) continue;
    matches.reference.push_back(reference.keypoints[slot.reference].pt);
    matches.current.push_back(current.keypoints[c].pt);
    matches.on_instances += label_of[slot.reference] != 0;
  }
  return matches;
}

}  // namespace edgeslam
