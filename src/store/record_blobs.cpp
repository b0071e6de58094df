#include "store/record_blobs.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#include "store/store_error.h"

namespace edgeslam {
namespace {

static_assert(std::endian::native == std::endian::little, "blobs are little-endian");

template <typename T>
void append(Blob& blob, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(&value);
  blob.insert(blob.end(), bytes, bytes + sizeof(T));
}

template <typename T>
T read(BlobView blob, std::size_t offset) {
  T value;
  std::memcpy(&value, blob.data() + offset, sizeof(T));
  return value;
}

void checkSize(BlobView blob, std::size_t element, const char* what) {
  if (blob.size() % element != 0) {
    throw StoreError(std::string("damaged ") + what + " blob (" + std::to_string(blob.size()) +
                     " bytes, not a multiple of " + std::to_string(element) + ")");
  }
}

constexpr std::size_t kKeyPointBytes = 6 * 4;
constexpr std::size_t kObservationBytes = 8 + 4;

}  // namespace

Blob poseBlob(const SE3d& T_cw) {
  Blob blob;
  blob.reserve(7 * sizeof(double));
  const Eigen::Quaterniond& q = T_cw.rotation();
  const Eigen::Vector3d& t = T_cw.translation();
  for (const double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) append(blob, v);
  return blob;
}

SE3d poseFromBlob(BlobView blob) {
  if (blob.size() != 7 * sizeof(double)) {
    throw StoreError("damaged pose blob (" + std::to_string(blob.size()) + " bytes)");
  }
  double v[7];
  std::memcpy(v, blob.data(), sizeof(v));
  return SE3d(Eigen::Quaterniond(v[6], v[3], v[4], v[5]), Eigen::Vector3d(v[0], v[1], v[2]));
}

Blob keypointsBlob(const std::vector<cv::KeyPoint>& keypoints) {
  Blob blob;
  blob.reserve(keypoints.size() * kKeyPointBytes);
  for (const cv::KeyPoint& k : keypoints) {
    append(blob, k.pt.x);
    append(blob, k.pt.y);
    append(blob, k.size);
    append(blob, k.angle);
    append(blob, k.response);
    append(blob, static_cast<std::int32_t>(k.octave));
  }
  return blob;
}

std::vector<cv::KeyPoint> keypointsFromBlob(BlobView blob) {
  checkSize(blob, kKeyPointBytes, "keypoints");
  std::vector<cv::KeyPoint> keypoints(blob.size() / kKeyPointBytes);
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const std::size_t o = i * kKeyPointBytes;
    cv::KeyPoint& k = keypoints[i];
    k.pt.x = read<float>(blob, o);
    k.pt.y = read<float>(blob, o + 4);
    k.size = read<float>(blob, o + 8);
    k.angle = read<float>(blob, o + 12);
    k.response = read<float>(blob, o + 16);
    k.octave = read<std::int32_t>(blob, o + 20);
  }
  return keypoints;
}

Blob descriptorsBlob(const cv::Mat& descriptors) {
  if (descriptors.empty()) return {};
  const cv::Mat rows = descriptors.isContinuous() ? descriptors : descriptors.clone();
  return Blob(rows.data, rows.data + rows.total() * rows.elemSize());
}

cv::Mat descriptorsFromBlob(BlobView blob) {
  checkSize(blob, 32, "descriptors");
  cv::Mat descriptors(static_cast<int>(blob.size() / 32), 32, CV_8U);
  if (!blob.empty()) std::memcpy(descriptors.data, blob.data(), blob.size());
  return descriptors;
}

Blob floatsBlob(const std::vector<float>& values) {
  Blob blob;
  blob.reserve(values.size() * sizeof(float));
  for (const float v : values) append(blob, v);
  return blob;
}

std::vector<float> floatsFromBlob(BlobView blob) {
  checkSize(blob, sizeof(float), "float array");
  std::vector<float> values(blob.size() / sizeof(float));
  if (!blob.empty()) std::memcpy(values.data(), blob.data(), blob.size());
  return values;
}

Blob observationsBlob(const std::vector<PointObservationRecord>& observations) {
  Blob blob;
  blob.reserve(observations.size() * kObservationBytes);
  for (const PointObservationRecord& o : observations) {
    append(blob, static_cast<std::uint64_t>(o.keyframe));
    append(blob, o.keypoint_index);
  }
  return blob;
}

std::vector<PointObservationRecord> observationsFromBlob(BlobView blob) {
  checkSize(blob, kObservationBytes, "observations");
  std::vector<PointObservationRecord> observations(blob.size() / kObservationBytes);
  for (std::size_t i = 0; i < observations.size(); ++i) {
    observations[i].keyframe = read<std::uint64_t>(blob, i * kObservationBytes);
    observations[i].keypoint_index = read<std::uint32_t>(blob, i * kObservationBytes + 8);
  }
  return observations;
}

Blob bowBlob(const BowVector& bow) {
  Blob blob;
  blob.reserve(bow.size() * (4 + 8));
  for (const BowEntry& e : bow) {
    append(blob, std::uint32_t{e.word});
    append(blob, e.weight);
  }
  return blob;
}

BowVector bowFromBlob(BlobView blob) {
  checkSize(blob, 4 + 8, "bag of words");
  BowVector bow;
  bow.entries.reserve(blob.size() / 12);
  for (std::size_t offset = 0; offset < blob.size(); offset += 12) {
    BowEntry e{read<std::uint32_t>(blob, offset), read<double>(blob, offset + 4)};
    if (!(std::isfinite(e.weight) && e.weight > 0.0) ||
        (!bow.entries.empty() && e.word <= bow.entries.back().word)) {
      throw StoreError("damaged bag of words blob (word " + std::to_string(e.word) + ")");
    }
    bow.entries.push_back(e);
  }
  return bow;
}

Blob featureVectorBlob(const FeatureVector& features) {
  Blob blob;
  blob.reserve(features.size() * 8 + features.featureCount() * 4);
  for (std::size_t i = 0; i < features.size(); ++i) {
    const auto indices = features.features(i);
    append(blob, std::uint32_t{features.node(i)});
    append(blob, static_cast<std::uint32_t>(indices.size()));
    for (const int index : indices) append(blob, static_cast<std::uint32_t>(index));
  }
  return blob;
}

FeatureVector featureVectorFromBlob(BlobView blob) {
  std::vector<std::pair<NodeId, int>> pairs;
  pairs.reserve(blob.size() / 4);  // at most one feature per 4 bytes
  std::size_t offset = 0;
  while (offset < blob.size()) {
    if (blob.size() - offset < 8) throw StoreError("damaged direct index blob (truncated node)");
    const auto node = read<std::uint32_t>(blob, offset);
    const auto count = read<std::uint32_t>(blob, offset + 4);
    offset += 8;
    if ((blob.size() - offset) / 4 < count) {
      throw StoreError("damaged direct index blob (node " + std::to_string(node) + ")");
    }
    for (std::uint32_t k = 0; k < count; ++k, offset += 4) {
      const auto index = read<std::uint32_t>(blob, offset);
      if (index > static_cast<std::uint32_t>(std::numeric_limits<int>::max())) {
        throw StoreError("damaged direct index blob (feature " + std::to_string(index) + ")");
      }
      pairs.emplace_back(node, static_cast<int>(index));
    }
  }
  return FeatureVector::fromPairs(std::move(pairs));
}

}  // namespace edgeslam
