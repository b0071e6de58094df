#include "server/omitted_descriptors.h"

#include <fmt/format.h>

#include <cstring>
#include <random>
#include <stdexcept>
#include <string>

namespace edgeslam {
namespace {

// Bits that no real descriptor nor another lost keypoint is close to (~128 bits from each): two
// zero rows would match each other at distance 0 in triangulation and fusion.
void fillWithNoise(std::uint8_t* row, std::uint64_t seed) {
  std::mt19937_64 bits(seed);
  for (int word = 0; word < 4; ++word) {
    const std::uint64_t value = bits();
    std::memcpy(row + 8 * word, &value, 8);
  }
}

}  // namespace

OmittedDescriptorFill fillOmittedDescriptors(const Map& map, KeyFrameRecord& keyframe) {
  OmittedDescriptorFill fill;
  KeyFrameFeaturesRecord& features = keyframe.features;
  std::vector<bool>& omitted = features.descriptor_omitted;
  if (omitted.empty()) return fill;
  const std::size_t n = features.keypoints.size();
  const std::string where = fmt::format("keyframe {:#x}: ", keyframe.id);
  if (omitted.size() != n) {
    throw std::invalid_argument(
        fmt::format("{}{} descriptor_omitted flags for {} keypoints", where, omitted.size(), n));
  }
  if (features.descriptors.rows != static_cast<int>(n) || features.descriptors.cols != 32 ||
      features.descriptors.type() != CV_8UC1) {
    throw std::invalid_argument(where + "descriptors must be one 32-byte row per keypoint");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (omitted[i] && (keyframe.point_ids.size() != n || keyframe.point_ids[i] == kInvalidId)) {
      throw std::invalid_argument(fmt::format(
          "{}keypoint {} has its descriptor left out but names no map point", where, i));
    }
  }
  features.descriptors = features.descriptors.clone();
  for (std::size_t i = 0; i < n; ++i) {
    if (!omitted[i]) continue;
    auto* row = features.descriptors.ptr<std::uint8_t>(static_cast<int>(i));
    const MapPoint* point = map.mapPoint(keyframe.point_ids[i]);
    const bool usable = point != nullptr && !point->isBad() && point->descriptor().cols == 32 &&
                        point->descriptor().type() == CV_8UC1;
    if (!usable) {
      fillWithNoise(row, keyframe.id * 0x100000001b3ULL + i);
      keyframe.point_ids[i] = kInvalidId;
      fill.lost.push_back(i);
      continue;
    }
    std::memcpy(row, point->descriptor().ptr<std::uint8_t>(0), 32);
    ++fill.filled;
  }
  omitted.clear();
  return fill;
}

}  // namespace edgeslam
