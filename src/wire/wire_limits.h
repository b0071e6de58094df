#pragma once
// Sanity bounds on incoming messages: anything beyond them is a malformed or hostile message, not
// a big map. The byte size of a whole message is bounded separately by gRPC (EdgeServerLimits).
#include <cstddef>

namespace edgeslam::wire_limits {

constexpr std::size_t kMaxKeypoints = 20000;          // per keyframe
constexpr std::size_t kMaxPointsPerMessage = 200000;  // new points of an upload, points of a slice
constexpr std::size_t kMaxKeyFramesPerSlice = 20000;
constexpr std::size_t kMaxObservations = 10000;  // per map point
constexpr std::size_t kMaxErasedPerSlice = 1000000;
constexpr std::size_t kMaxMasksPerSlice = 1000;
constexpr std::size_t kMaxLoopsPerSlice = 1000;
constexpr std::size_t kMaxClientMapKeyFrames = 100000;  // SessionSettings.client_map_keyframes
constexpr int kMaxPyramidLevels = 32;
constexpr int kMaxImageSide = 16384;  // camera and mask width / height
constexpr std::size_t kDescriptorBytes = 32;

}  // namespace edgeslam::wire_limits
