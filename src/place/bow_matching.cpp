#include "place/bow_matching.h"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <stdexcept>

#include "features/descriptor_distance.h"
#include "features/descriptor_matching.h"

namespace edgeslam {
namespace {

void checkDescriptors(const cv::Mat& descriptors, const FeatureVector& features, const char* name) {
  if (features.empty()) return;
  if (descriptors.type() != CV_8UC1 || descriptors.cols != kDescriptorBytes) {
    throw std::invalid_argument(fmt::format(
        "matchByBow: descriptors {} must be CV_8UC1 with {} columns, got type {} with {} columns",
        name, kDescriptorBytes, descriptors.type(), descriptors.cols));
  }
  for (std::size_t i = 0; i < features.size(); ++i) {
    for (const int f : features.features(i)) {
      if (f < 0 || f >= descriptors.rows) {
        throw std::invalid_argument(
            fmt::format("matchByBow: feature index {} of image {} outside its {} descriptors", f,
                        name, descriptors.rows));
      }
    }
  }
}

}  // namespace

std::vector<cv::DMatch> matchByBow(const FeatureVector& features_a, const cv::Mat& descriptors_a,
                                   const FeatureVector& features_b, const cv::Mat& descriptors_b,
                                   const BowMatchOptions& options) {
  checkDescriptors(descriptors_a, features_a, "A");
  checkDescriptors(descriptors_b, features_b, "B");
  // Best A feature proposing each B feature.
  std::vector<cv::DMatch> best_for_b(static_cast<std::size_t>(std::max(descriptors_b.rows, 0)),
                                     cv::DMatch(-1, -1, static_cast<float>(INT_MAX)));
  std::size_t ia = 0;
  std::size_t ib = 0;
  while (ia < features_a.size() && ib < features_b.size()) {
    if (features_a.node(ia) < features_b.node(ib)) {
      ++ia;
      continue;
    }
    if (features_b.node(ib) < features_a.node(ia)) {
      ++ib;
      continue;
    }
    const auto candidates_b = features_b.features(ib);
    for (const int a : features_a.features(ia)) {
      const std::uint8_t* da = descriptors_a.ptr<std::uint8_t>(a);
      int best = INT_MAX;
      int second = INT_MAX;
      int best_b = -1;
      for (const int b : candidates_b) {
        const int distance = descriptorDistance(da, descriptors_b.ptr<std::uint8_t>(b));
        if (distance < best) {
          second = best;
          best = distance;
          best_b = b;
        } else if (distance < second) {
          second = distance;
        }
      }
      if (best_b < 0 || best > options.max_distance) continue;
      if (second != INT_MAX && !(best < options.ratio * second)) continue;
      cv::DMatch& slot = best_for_b[static_cast<std::size_t>(best_b)];
      if (best < slot.distance || (best == slot.distance && a < slot.queryIdx)) {
        slot = cv::DMatch(a, best_b, static_cast<float>(best));
      }
    }
    ++ia;
    ++ib;
  }
  std::vector<cv::DMatch> matches;
  for (const cv::DMatch& m : best_for_b) {
    if (m.queryIdx >= 0) matches.push_back(m);
  }
  std::sort(matches.begin(), matches.end(),
            [](const cv::DMatch& x, const cv::DMatch& y) { return x.queryIdx < y.queryIdx; });
  return matches;
}

std::vector<cv::DMatch> matchByBow(const FeatureVector& features_a,
                                   std::span<const cv::KeyPoint> keypoints_a,
                                   const cv::Mat& descriptors_a, const FeatureVector& features_b,
                                   std::span<const cv::KeyPoint> keypoints_b,
                                   const cv::Mat& descriptors_b, const BowMatchOptions& options) {
  if (keypoints_a.size() != static_cast<std::size_t>(descriptors_a.rows) ||
      keypoints_b.size() != static_cast<std::size_t>(descriptors_b.rows)) {
    throw std::invalid_argument(
        fmt::format("matchByBow: {} / {} keypoints for {} / {} descriptor rows", keypoints_a.size(),
                    keypoints_b.size(), descriptors_a.rows, descriptors_b.rows));
  }
  std::vector<cv::DMatch> matches =
      matchByBow(features_a, descriptors_a, features_b, descriptors_b, options);
  if (options.check_orientation) {
    matches = filterByRotation(matches, keypoints_a, keypoints_b, options.rotation_bins);
    std::sort(matches.begin(), matches.end(),
              [](const cv::DMatch& x, const cv::DMatch& y) { return x.queryIdx < y.queryIdx; });
  }
  return matches;
}

}  // namespace edgeslam
