#pragma once
// Map records as typed blobs: arrays of fixed-size little-endian values (a keyframe's keypoints
// in one blob, its descriptors as an N x 32 row-major matrix in another), never a row per keypoint.
// Decoding throws StoreError when a blob's size is not a whole number of elements.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "map/map_records.h"
#include "place/bow_vector.h"
#include "place/feature_vector.h"

namespace edgeslam {

using Blob = std::vector<std::uint8_t>;
// What a decoder reads: a Blob, or a column of a row in place (no copy).
using BlobView = std::span<const std::uint8_t>;

Blob poseBlob(const SE3d& T_cw);
SE3d poseFromBlob(BlobView blob);

Blob keypointsBlob(const std::vector<cv::KeyPoint>& keypoints);
std::vector<cv::KeyPoint> keypointsFromBlob(BlobView blob);

Blob descriptorsBlob(const cv::Mat& descriptors);  // N x 32 CV_8U
cv::Mat descriptorsFromBlob(BlobView blob);

Blob floatsBlob(const std::vector<float>& values);
std::vector<float> floatsFromBlob(BlobView blob);

Blob observationsBlob(const std::vector<PointObservationRecord>& observations);
std::vector<PointObservationRecord> observationsFromBlob(BlobView blob);

// 12 B a word: u32 word, f64 weight. Decoding keeps the order (words ascending, as written).
Blob bowBlob(const BowVector& bow);
BowVector bowFromBlob(BlobView blob);

// Per node: u32 node, u32 count, count x u32 feature index.
Blob featureVectorBlob(const FeatureVector& features);
FeatureVector featureVectorFromBlob(BlobView blob);

}  // namespace edgeslam
