// Map's bulk load: a stored session's points created without recording each change, and the
// covisibility graph of every keyframe linked in one pass (as updateConnections, keyframe by
// keyframe in id order, would link it).
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <unordered_map>
#include <utility>
#include <vector>

#include "map/map.h"

namespace edgeslam {

namespace {

// A loaded point's descriptor: a row of a block of a few thousand, which the row keeps alive, in
// place of two allocations (header and bytes) per point, a fifth of creating a stored map's points.
// Rows are only read or replaced whole (MapPoint gives each new descriptor its own matrix).
cv::Mat descriptorRow(const std::uint8_t* bytes) {
  constexpr int kRowsPerBlock = 4096;
  thread_local cv::Mat block;
  thread_local int next = kRowsPerBlock;
  if (next == kRowsPerBlock) {
    block = cv::Mat(kRowsPerBlock, 32, CV_8U);
    next = 0;
  }
  cv::Mat row = block.row(next++);
  std::memcpy(row.data, bytes, 32);
  return row;
}

}  // namespace

MapPoint* Map::loadPoint(const PointLoad& load) {
  MapPointId id = load.id;
  if (id == kInvalidId) {
    id = ids_.next();
  } else {
    ids_.advancePast(id);
  }
  auto owned = std::make_unique<MapPoint>(id, load.position, load.reference);
  MapPoint* point = owned.get();
  if (!points_.emplace(id, std::move(owned)).second) {
    throw std::logic_error("Map: duplicate map point id");
  }
  // The observers' keypoint slots and depths lie far apart: fetched together, not one cache miss
  // after the other (they were most of the time of loading the points).
  for (const auto& [keyframe, index] : load.observers) {
    __builtin_prefetch(keyframe->points_.data() + index);
    const std::vector<float>& depth = keyframe->features_->depth;
    if (index < depth.size()) __builtin_prefetch(depth.data() + index);
  }
  for (const auto& [keyframe, index] : load.observers) {
    MapPoint*& slot = keyframe->points_[index];
    if (slot == nullptr && !keyframe->isBad()) {
      const std::size_t before = point->observations_.size();
      // Observations come in keyframe id order: each goes at the end.
      point->observations_.emplace_hint(point->observations_.end(), keyframe->id(),
                                        MapPoint::Observation{keyframe, index});
      if (point->observations_.size() > before) {
        point->observation_weight_ += keyframe->features().hasDepth(index) ? 2 : 1;
        slot = point;
        continue;
      }
    }
    // A keypoint another point holds, a keyframe named twice: addObservation's rules.
    const bool recording = std::exchange(recording_, false);
    addObservation(point, keyframe, index);
    recording_ = recording;
  }
  point->normal_ = load.normal;
  point->descriptor_ = descriptorRow(load.descriptor);
  point->min_distance_ = load.min_distance;
  point->max_distance_ = load.max_distance;
  return point;
}

namespace {

using Weighted = std::pair<std::uint32_t, int>;  // a keyframe's index in id order, a weight

// Each keyframe's points as rows of a flat table of their observers (keyframe indices): what
// updateConnections reads of every point it walks, gathered once instead of once per observer.
struct Observers {
  std::vector<std::uint32_t> row_start;       // per point row, into keyframes; one more at the end
  std::vector<std::uint32_t> keyframes;       // the observers of each row, in id order
  std::vector<std::uint32_t> keyframe_rows;   // the rows of each keyframe's points
  std::vector<std::uint32_t> keyframe_start;  // per keyframe, into keyframe_rows; one more
};

}  // namespace

void Map::linkAllConnections() {
  const std::vector<KeyFrame*> keyframes = keyFrames();
  const bool unlinked = std::all_of(keyframes.begin(), keyframes.end(), [](const KeyFrame* kf) {
    return kf->connection_weights_.empty() && kf->parent_ == nullptr && kf->first_connection_;
  });
  if (!unlinked) {  // links to update, not to make: one keyframe at a time
    for (KeyFrame* keyframe : keyframes) updateConnections(keyframe);
    return;
  }
  const auto n = static_cast<std::uint32_t>(keyframes.size());
  std::unordered_map<const KeyFrame*, std::uint32_t> index_of;
  index_of.reserve(n);
  for (std::uint32_t i = 0; i < n; ++i) index_of.emplace(keyframes[i], i);

  Observers table;
  table.row_start.reserve(points_.size() + 1);
  table.keyframes.reserve(points_.size() * 4);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> memberships;  // keyframe, row
  memberships.reserve(points_.size() * 4);
  for (const auto& [id, point] : points_) {
    if (point->isBad()) continue;
    const auto row = static_cast<std::uint32_t>(table.row_start.size());
    table.row_start.push_back(static_cast<std::uint32_t>(table.keyframes.size()));
    for (const auto& [keyframe_id, obs] : point->observations_) {
      if (obs.keyframe->isBad()) continue;
      const auto it = index_of.find(obs.keyframe);
      if (it == index_of.end()) continue;
      table.keyframes.push_back(it->second);
      // (The keypoint links the point back: Map keeps both sides in step.)
      memberships.emplace_back(it->second, row);
    }
  }
  table.row_start.push_back(static_cast<std::uint32_t>(table.keyframes.size()));
  table.keyframe_start.assign(n + 1, 0);
  for (const auto& [keyframe, row] : memberships) ++table.keyframe_start[keyframe + 1];
  for (std::uint32_t i = 0; i < n; ++i) table.keyframe_start[i + 1] += table.keyframe_start[i];
  table.keyframe_rows.resize(memberships.size());
  {
    std::vector<std::uint32_t> next(table.keyframe_start.begin(), table.keyframe_start.end() - 1);
    for (const auto& [keyframe, row] : memberships) table.keyframe_rows[next[keyframe]++] = row;
  }

  // What each keyframe's updateConnections would keep (weights of 15 or more, else its strongest
  // link) and the parent it would take. Run in id order, a later keyframe's links overwrite an
  // earlier one's: the link of keyframes a < b exists when b keeps a, with their shared weight.
  constexpr int kMinWeight = 15;
  std::vector<std::vector<Weighted>> kept(n);
  std::vector<int> shared(n, 0);
  std::vector<std::uint32_t> counted;
  for (std::uint32_t k = 0; k < n; ++k) {
    counted.clear();
    for (std::uint32_t r = table.keyframe_start[k]; r < table.keyframe_start[k + 1]; ++r) {
      const std::uint32_t row = table.keyframe_rows[r];
      for (std::uint32_t o = table.row_start[row]; o < table.row_start[row + 1]; ++o) {
        const std::uint32_t other = table.keyframes[o];
        if (other != k && shared[other]++ == 0) counted.push_back(other);
      }
    }
    if (counted.empty()) continue;
    std::sort(counted.begin(), counted.end());
    std::uint32_t strongest = 0;
    int strongest_weight = 0;
    for (const std::uint32_t other : counted) {
      const int w = std::exchange(shared[other], 0);
      if (w > strongest_weight) {
        strongest_weight = w;
        strongest = other;
      }
      if (w >= kMinWeight) kept[k].emplace_back(other, w);
    }
    if (kept[k].empty()) kept[k].emplace_back(strongest, strongest_weight);
    if (strongest < k) {
      keyframes[k]->parent_ = keyframes[strongest];
      keyframes[strongest]->children_.insert(keyframes[k]);
      keyframes[k]->first_connection_ = false;
    }
  }

  // Each keyframe's links in id order (those to earlier keyframes come first, then the later
  // ones in the order they are met); ordered by weight, ties in id order, as updateConnections
  // leaves them.
  std::vector<std::vector<Weighted>> links(n);
  for (std::uint32_t b = 0; b < n; ++b) {
    for (const auto& [a, w] : kept[b]) {
      if (a >= b) break;
      links[b].emplace_back(a, w);
      links[a].emplace_back(b, w);
    }
  }
  for (std::uint32_t k = 0; k < n; ++k) {
    KeyFrame* keyframe = keyframes[k];
    keyframe->ordered_connections_.reserve(links[k].size());
    for (const auto& [other, w] : links[k]) {
      keyframe->connection_weights_.emplace_hint(keyframe->connection_weights_.end(),
                                                 keyframes[other], w);
      keyframe->ordered_connections_.emplace_back(w, keyframes[other]);
    }
    std::stable_sort(keyframe->ordered_connections_.begin(), keyframe->ordered_connections_.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
  }
}

}  // namespace edgeslam
