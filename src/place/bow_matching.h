#pragma once
// Descriptor matching between two images accelerated by their direct indexes: only features filed
// under the same vocabulary node are compared.
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "place/feature_vector.h"

namespace edgeslam {

struct BowMatchOptions {
  int max_distance = 50;  // Hamming, of 256 bits
  double ratio = 0.75;    // best < ratio * second best within the node; 1 disables the test
  // Keypoint version only: keep the matches whose angle change falls in the dominant bins of a
  // rotation histogram (features/descriptor_matching.h filterByRotation).
  bool check_orientation = true;
  int rotation_bins = 30;
};

// For every feature of image A, the closest feature of image B under the same node, kept when it
// is within max_distance and passes the ratio test; then one-to-one: each B feature keeps only its
// closest A feature (the lower A index on ties). queryIdx indexes `descriptors_a`, trainIdx
// `descriptors_b`, distance is the Hamming distance; sorted by queryIdx. Both FeatureVectors must
// come from the same vocabulary at the same level. Throws std::invalid_argument for descriptor
// matrices that are not CV_8UC1 x 32 or an index out of range.
std::vector<cv::DMatch> matchByBow(const FeatureVector& features_a, const cv::Mat& descriptors_a,
                                   const FeatureVector& features_b, const cv::Mat& descriptors_b,
                                   const BowMatchOptions& options = {});

// The same, then the rotation-consistency filter when options.check_orientation is set. Keypoints
// are indexed like the descriptor rows.
std::vector<cv::DMatch> matchByBow(const FeatureVector& features_a,
                                   std::span<const cv::KeyPoint> keypoints_a,
                                   const cv::Mat& descriptors_a, const FeatureVector& features_b,
                                   std::span<const cv::KeyPoint> keypoints_b,
                                   const cv::Mat& descriptors_b,
                                   const BowMatchOptions& options = {});

}  // namespace edgeslam
