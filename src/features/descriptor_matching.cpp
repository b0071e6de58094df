#include "features/descriptor_matching.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "features/descriptor_distance.h"
#include "features/rotation_histogram.h"

namespace edgeslam {
namespace {

void requireDescriptors(const cv::Mat& descriptors, std::size_t keypoints, const char* which) {
  if (descriptors.empty() && keypoints == 0) return;
  if (descriptors.type() != CV_8UC1 || descriptors.cols != kDescriptorBytes ||
      static_cast<std::size_t>(descriptors.rows) != keypoints) {
    throw std::invalid_argument(
        fmt::format("matching: {} descriptors must be CV_8UC1 with 32 columns and one row per "
                    "keypoint (got {} {}x{} for {} keypoints)",
                    which, cv::typeToString(descriptors.type()), descriptors.rows, descriptors.cols,
                    keypoints));
  }
}

void consider(BestTwo& best, int index, int distance) {
  if (distance < best.distance) {
    best.second_distance = best.distance;
    best.distance = distance;
    best.index = index;
  } else if (distance < best.second_distance) {
    best.second_distance = distance;
  }
}

// Accepts a match unless the train row already has a closer one; a replaced match is dropped.
class OnePerTrain {
 public:
  explicit OnePerTrain(int train_size) : query_of_(train_size, -1), distance_of_(train_size, 0) {}
  void offer(int query, int train, int distance) {
    if (query_of_[train] >= 0 && distance_of_[train] <= distance) return;
    query_of_[train] = query;
    distance_of_[train] = distance;
  }
  std::vector<cv::DMatch> matches() const {
    std::vector<cv::DMatch> out;
    for (int t = 0; t < static_cast<int>(query_of_.size()); ++t) {
      if (query_of_[t] >= 0) {
        out.emplace_back(query_of_[t], t, static_cast<float>(distance_of_[t]));
      }
    }
    return out;
  }

 private:
  std::vector<int> query_of_;
  std::vector<int> distance_of_;
};

std::vector<cv::DMatch> finish(const OnePerTrain& accepted, const MatchOptions& options,
                               std::span<const cv::KeyPoint> query_keypoints,
                               std::span<const cv::KeyPoint> train_keypoints) {
  std::vector<cv::DMatch> matches = accepted.matches();
  if (options.check_orientation) {
    matches = filterByRotation(matches, query_keypoints, train_keypoints, options.rotation_bins);
  }
  return matches;
}

}  // namespace

BestTwo findBestTwo(const std::uint8_t* query, const cv::Mat& descriptors,
                    std::span<const int> candidates) {
  BestTwo best;
  for (const int row : candidates) {
    consider(best, row, descriptorDistance(query, descriptors.ptr<std::uint8_t>(row)));
  }
  return best;
}

BestTwo findBestTwo(const std::uint8_t* query, const cv::Mat& descriptors) {
  BestTwo best;
  for (int row = 0; row < descriptors.rows; ++row) {
    consider(best, row, descriptorDistance(query, descriptors.ptr<std::uint8_t>(row)));
  }
  return best;
}

std::vector<cv::DMatch> filterByRotation(const std::vector<cv::DMatch>& matches,
                                         std::span<const cv::KeyPoint> query_keypoints,
                                         std::span<const cv::KeyPoint> train_keypoints, int bins) {
  RotationHistogram histogram(bins);
  for (int m = 0; m < static_cast<int>(matches.size()); ++m) {
    const cv::DMatch& match = matches[m];
    if (match.queryIdx < 0 || match.trainIdx < 0 ||
        static_cast<std::size_t>(match.queryIdx) >= query_keypoints.size() ||
        static_cast<std::size_t>(match.trainIdx) >= train_keypoints.size()) {
      throw std::invalid_argument(fmt::format(
          "rotation filter: match {} refers to keypoints {} / {} of {} / {}", m, match.queryIdx,
          match.trainIdx, query_keypoints.size(), train_keypoints.size()));
    }
    histogram.add(query_keypoints[match.queryIdx].angle, train_keypoints[match.trainIdx].angle, m);
  }
  std::vector<int> kept = histogram.consistent();
  std::sort(kept.begin(), kept.end());
  std::vector<cv::DMatch> out;
  out.reserve(kept.size());
  for (const int m : kept) out.push_back(matches[m]);
  return out;
}

std::vector<cv::DMatch> matchBruteForce(std::span<const cv::KeyPoint> query_keypoints,
                                        const cv::Mat& query_descriptors,
                                        std::span<const cv::KeyPoint> train_keypoints,
                                        const cv::Mat& train_descriptors,
                                        const MatchOptions& options) {
  requireDescriptors(query_descriptors, query_keypoints.size(), "query");
  requireDescriptors(train_descriptors, train_keypoints.size(), "train");
  OnePerTrain accepted(train_descriptors.rows);
  for (int q = 0; q < query_descriptors.rows; ++q) {
    const BestTwo best = findBestTwo(query_descriptors.ptr<std::uint8_t>(q), train_descriptors);
    if (best.index >= 0 && best.distance <= options.max_distance &&
        best.passesRatio(options.ratio)) {
      accepted.offer(q, best.index, best.distance);
    }
  }
  return finish(accepted, options, query_keypoints, train_keypoints);
}

std::vector<cv::DMatch> matchInWindow(std::span<const cv::KeyPoint> query_keypoints,
                                      const cv::Mat& query_descriptors,
                                      std::span<const cv::KeyPoint> train_keypoints,
                                      const cv::Mat& train_descriptors,
                                      const FeatureGrid& train_grid, float radius,
                                      const MatchOptions& options, int level_tolerance) {
  requireDescriptors(query_descriptors, query_keypoints.size(), "query");
  requireDescriptors(train_descriptors, train_keypoints.size(), "train");
  if (train_grid.size() != train_keypoints.size()) {
    throw std::invalid_argument(
        fmt::format("matching: the grid holds {} keypoints but there are {} train keypoints",
                    train_grid.size(), train_keypoints.size()));
  }
  OnePerTrain accepted(train_descriptors.rows);
  std::vector<int> candidates;
  for (int q = 0; q < static_cast<int>(query_keypoints.size()); ++q) {
    const cv::KeyPoint& kp = query_keypoints[q];
    train_grid.featuresInArea(kp.pt.x, kp.pt.y, radius, std::max(0, kp.octave - level_tolerance),
                              kp.octave + level_tolerance, candidates);
    const BestTwo best =
        findBestTwo(query_descriptors.ptr<std::uint8_t>(q), train_descriptors, candidates);
    if (best.index >= 0 && best.distance <= options.max_distance &&
        best.passesRatio(options.ratio)) {
      accepted.offer(q, best.index, best.distance);
    }
  }
  return finish(accepted, options, query_keypoints, train_keypoints);
}

}  // namespace edgeslam
