#pragma once
// Map records as typed blobs: arrays of fixed-size little-endian values (a keyframe's keypoints
// in one blob, its descriptors as an N x 32 row-major matrix in another), never a row per keypoint.
// Decoding throws StoreError when a blob's size is not a whole number of elements.
#include <cstdint>
#include <string>
#include <vector>

#include "map/map_records.h"
#include "place/bow_vector.h"
#include "place/feature_vector.h"

namespace edgeslam {

using Blob = std::vector<std::uint8_t>;

Blob poseBlob(const SE3d& T_cw);
SE3d poseFromBlob(const Blob& blob);

Blob keypointsBlob(const std::vector<cv::KeyPoint>& keypoints);
std::vector<cv::KeyPoint> keypointsFromBlob(const Blob& blob);

Blob descriptorsBlob(const cv::Mat& descriptors);  // N x 32 CV_8U
cv::Mat descriptorsFromBlob(const Blob& blob);

Blob floatsBlob(const std::vector<float>& values);
std::vector<float> floatsFromBlob(const Blob& blob);

Blob observationsBlob(const std::vector<PointObservationRecord>& observations);
std::vector<PointObservationRecord> observationsFromBlob(const Blob& blob);

// 12 B a word: u32 word, f64 weight. Decoding keeps the order (words ascending, as written).
Blob bowBlob(const BowVector& bow);
BowVector bowFromBlob(const Blob& blob);

// Per node: u32 node, u32 count, count x u32 feature index.
Blob featureVectorBlob(const FeatureVector& features);
FeatureVector featureVectorFromBlob(const Blob& blob);

}  // namespace edgeslam
