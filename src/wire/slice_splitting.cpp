#include "wire/slice_splitting.h"

#include <fmt/format.h>

#include <iterator>
#include <utility>

#include "wire/wire_convert.h"
#include "wire/wire_error.h"

namespace edgeslam {
namespace {

template <typename T>
void moveFirstHalf(std::vector<T>& from, std::vector<T>& to) {
  const std::size_t n = (from.size() + 1) / 2;
  to.assign(std::make_move_iterator(from.begin()),
            std::make_move_iterator(from.begin() + static_cast<std::ptrdiff_t>(n)));
  from.erase(from.begin(), from.begin() + static_cast<std::ptrdiff_t>(n));
}

bool hasRecords(const MapSlice& s) {
  return !s.keyframes.empty() || !s.points_upserted.empty() || !s.point_positions.empty() ||
         !s.masks.empty();
}

// Moves the first half of the first non-empty record list into a records-only part.
MapSlice takeRecords(MapSlice& slice) {
  MapSlice part;
  part.newest_keyframe = slice.newest_keyframe;  // how the client reads the points' observations
  if (!slice.keyframes.empty()) {
    moveFirstHalf(slice.keyframes, part.keyframes);
  } else if (!slice.points_upserted.empty()) {
    moveFirstHalf(slice.points_upserted, part.points_upserted);
  } else if (!slice.point_positions.empty()) {
    moveFirstHalf(slice.point_positions, part.point_positions);
  } else {
    moveFirstHalf(slice.masks, part.masks);
  }
  return part;
}

bool onlyRecords(const MapSlice& s) {
  return s.upload_sequence == 0 && s.processed_keyframe == kInvalidId && !s.full_resync &&
         s.points_erased.empty() && s.keyframe_poses.empty() && s.keyframes_erased.empty() &&
         s.keyframes_evicted.empty() && !s.reference_pose && s.loops_closed == 0 &&
         s.maps_merged == 0 && s.loops.empty() && s.map_keyframes == 0 && s.map_points == 0 &&
         !s.localization;
}

std::size_t recordCount(const MapSlice& s) {
  return s.keyframes.size() + s.points_upserted.size() + s.point_positions.size() + s.masks.size();
}

void split(MapSlice slice, std::size_t max_bytes,
           const std::function<std::size_t(const MapSlice&)>& size, std::vector<MapSlice>& out) {
  const std::size_t bytes = size(slice);
  if (bytes <= max_bytes) {
    out.push_back(std::move(slice));
    return;
  }
  if (!hasRecords(slice) || (recordCount(slice) == 1 && onlyRecords(slice))) {
    throw SliceTooLarge(fmt::format(
        "map slice of {} bytes exceeds the {} bytes one message may carry, and {}", bytes,
        max_bytes, hasRecords(slice) ? "one record alone is that large" : "it has no records"));
  }
  MapSlice records = takeRecords(slice);
  split(std::move(records), max_bytes, size, out);
  split(std::move(slice), max_bytes, size, out);
}

}  // namespace

std::vector<MapSlice> splitSlice(MapSlice slice, std::size_t max_bytes,
                                 const std::function<std::size_t(const MapSlice&)>& size) {
  std::vector<MapSlice> parts;
  split(std::move(slice), max_bytes, size, parts);
  return parts;
}

// Generous per-record bounds of the encoded size (wire.md, Sizes), so that only slices that may
// be too big are measured exactly (encoding costs as much as sending).
std::size_t sizeBound(const MapSlice& s) {
  std::size_t bytes = 1024;
  for (const KeyFrameRecord& k : s.keyframes) bytes += 256 + 64 * k.features.keypoints.size();
  for (const MapPointRecord& p : s.points_upserted) bytes += 128 + 24 * p.observations.size();
  bytes += 32 * s.point_positions.size() + 64 * s.keyframe_poses.size();
  bytes += 16 * (s.points_erased.size() + s.keyframes_erased.size() + s.keyframes_evicted.size());
  for (const MaskRecord& m : s.masks) bytes += 64 + m.bytes.size();
  return bytes;
}

SlicePushResult pushSplitting(SliceSink& sink, MapSlice slice) {
  const std::size_t max_bytes = sink.maxSliceBytes();
  if (sizeBound(slice) <= max_bytes) {
    sink.push(std::move(slice));
    return {1, true};
  }
  const auto size = [](const MapSlice& s) { return wireSize(s); };
  std::vector<MapSlice> parts = splitSlice(std::move(slice), max_bytes, size);
  for (MapSlice& part : parts) sink.push(std::move(part));
  return {parts.size(), true};
}

}  // namespace edgeslam
