#pragma once
// Descriptor matching building blocks that need no map types: best/second-best search with a
// ratio test, and two matchers (brute force, window around the same position) that keep one match
// per train feature and can filter by rotation consistency.
#include <climits>
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "features/feature_grid.h"

namespace edgeslam {

// Hamming thresholds (of 256 bits) for a confident and for a loose match.
inline constexpr int kMatchDistanceLow = 50;
inline constexpr int kMatchDistanceHigh = 100;

struct BestTwo {
  int index = -1;  // candidate with the smallest distance, -1 when there was none
  int distance = INT_MAX;
  int second_distance = INT_MAX;  // INT_MAX when there was a single candidate

  // best < ratio * second (always true with a single candidate).
  bool passesRatio(double ratio) const {
    return index >= 0 && (second_distance == INT_MAX || distance < ratio * second_distance);
  }
};

// Among rows `candidates` of `descriptors` (CV_8UC1, 32 columns).
BestTwo findBestTwo(const std::uint8_t* query, const cv::Mat& descriptors,
                    std::span<const int> candidates);
// Among all rows of `descriptors`.
BestTwo findBestTwo(const std::uint8_t* query, const cv::Mat& descriptors);

struct MatchOptions {
  int max_distance = kMatchDistanceLow;
  double ratio = 0.9;  // best / second best; 1 disables the test
  bool check_orientation = true;
  int rotation_bins = 30;
};

// Keeps the matches whose angle change lies in the dominant bins of a RotationHistogram.
std::vector<cv::DMatch> filterByRotation(const std::vector<cv::DMatch>& matches,
                                         std::span<const cv::KeyPoint> query_keypoints,
                                         std::span<const cv::KeyPoint> train_keypoints,
                                         int bins = 30);

// Every query descriptor against every train descriptor. queryIdx / trainIdx index the rows;
// at most one match per train row (the closest). Keypoints are needed only for the rotation check.
std::vector<cv::DMatch> matchBruteForce(std::span<const cv::KeyPoint> query_keypoints,
                                        const cv::Mat& query_descriptors,
                                        std::span<const cv::KeyPoint> train_keypoints,
                                        const cv::Mat& train_descriptors,
                                        const MatchOptions& options = {});

// Each query keypoint against the train keypoints within `radius` of its own position (square
// window, see FeatureGrid) whose level differs by at most `level_tolerance`: the initialisation
// search between two nearby frames. `train_grid` must index `train_keypoints`.
std::vector<cv::DMatch> matchInWindow(std::span<const cv::KeyPoint> query_keypoints,
                                      const cv::Mat& query_descriptors,
                                      std::span<const cv::KeyPoint> train_keypoints,
                                      const cv::Mat& train_descriptors,
                                      const FeatureGrid& train_grid, float radius,
                                      const MatchOptions& options = {}, int level_tolerance = 0);

}  // namespace edgeslam
