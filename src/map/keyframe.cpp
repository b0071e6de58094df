#include "map/keyframe.h"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <utility>
#include <vector>

#include "map/map_point.h"

namespace edgeslam {

KeyFrame::KeyFrame(KeyFrameId id, std::size_t frame_index, double timestamp,
                   std::shared_ptr<const FrameFeatures> features, const SE3d& T_cw)
    : id_(id),
      frame_index_(frame_index),
      timestamp_(timestamp),
      features_(std::move(features)),
      T_cw_(T_cw),
      T_wc_(T_cw.inverse()),
      points_(features_->size(), nullptr) {}

void KeyFrame::setPose(const SE3d& T_cw) {
  T_cw_ = T_cw;
  T_wc_ = T_cw.inverse();
}

void KeyFrame::dropFeatures() {
  auto empty = std::make_shared<FrameFeatures>();
  empty->scales = features_->scales;
  empty->bf = features_->bf;
  features_ = std::move(empty);
  points_.clear();
  points_.shrink_to_fit();
  connection_weights_.clear();
  ordered_connections_.clear();
  ordered_connections_.shrink_to_fit();
}

SE3d KeyFrame::latestPose() const {
  SE3d relative;
  const KeyFrame* kf = this;
  // Erased keyframes keep their pose relative to the parent they had; walk up to a live one.
  for (int guard = 0; kf->bad_ && kf->parent_ != nullptr && guard < 100000; ++guard) {
    relative = relative * kf->T_cp_;
    kf = kf->parent_;
  }
  return relative * kf->T_cw_;
}

std::vector<MapPoint*> KeyFrame::goodPoints() const {
  std::vector<MapPoint*> out;
  out.reserve(points_.size());
  for (MapPoint* p : points_) {
    if (p != nullptr && !p->isBad()) out.push_back(p);
  }
  return out;
}

int KeyFrame::trackedPointCount(int min_observations) const {
  int count = 0;
  for (MapPoint* p : points_) {
    if (p != nullptr && !p->isBad() && p->observationCount() >= min_observations) ++count;
  }
  return count;
}

double KeyFrame::medianSceneDepth() const {
  std::vector<double> depths;
  depths.reserve(points_.size());
  const Eigen::Matrix3d R = T_cw_.rotationMatrix();
  const Eigen::Vector3d t = T_cw_.translation();
  for (MapPoint* p : points_) {
    if (p == nullptr || p->isBad()) continue;
    depths.push_back((R * p->position() + t).z());
  }
  if (depths.empty()) return 0.0;
  const auto mid = depths.begin() + static_cast<long>(depths.size() / 2);
  std::nth_element(depths.begin(), mid, depths.end());
  return *mid;
}

std::vector<KeyFrame*> KeyFrame::bestCovisibles(std::size_t n) const {
  std::vector<KeyFrame*> out;
  for (const auto& [w, kf] : ordered_connections_) {
    if (out.size() >= n) break;
    if (!kf->isBad()) out.push_back(kf);
  }
  return out;
}

std::vector<KeyFrame*> KeyFrame::covisiblesWithWeightAtLeast(int min_weight) const {
  std::vector<KeyFrame*> out;
  for (const auto& [w, kf] : ordered_connections_) {
    if (w < min_weight) break;
    if (!kf->isBad()) out.push_back(kf);
  }
  return out;
}

int KeyFrame::weight(KeyFrame* other) const {
  const auto it = connection_weights_.find(other);
  return it == connection_weights_.end() ? 0 : it->second;
}

void KeyFrame::updateConnections() {
  // The points shared with each other keyframe, counted in a small open-addressing table keyed by
  // address: no sort of every observer (by id, that sort was half of loading a stored
  // 1000-keyframe map), no keyframe read per observation. The few keyframes counted are put in id
  // order after.
  std::vector<std::pair<KeyFrame*, int>> table(256, {nullptr, 0});
  std::size_t distinct = 0;
  const auto slotOf = [&table](const KeyFrame* kf) {
    // Fibonacci hashing of the address, then linear probing.
    const std::size_t mask = table.size() - 1;
    std::size_t slot = (reinterpret_cast<std::uintptr_t>(kf) * 0x9E3779B97F4A7C15ull) >>
                       (64 - std::countr_zero(table.size()));
    while (table[slot].first != nullptr && table[slot].first != kf) slot = (slot + 1) & mask;
    return slot;
  };
  for (MapPoint* p : points_) {
    if (p == nullptr || p->isBad()) continue;
    for (const auto& [id, obs] : p->observations()) {
      KeyFrame* kf = obs.keyframe;
      if (kf == this || kf->isBad()) continue;
      std::size_t slot = slotOf(kf);
      if (table[slot].first == nullptr) {
        if (2 * (distinct + 1) > table.size()) {  // at most half full: grow
          std::vector<std::pair<KeyFrame*, int>> old(table.size() * 2, {nullptr, 0});
          table.swap(old);
          for (const auto& entry : old) {
            if (entry.first != nullptr) table[slotOf(entry.first)] = entry;
          }
          slot = slotOf(kf);
        }
        table[slot].first = kf;
        ++distinct;
      }
      ++table[slot].second;
    }
  }
  if (distinct == 0) return;
  std::vector<std::pair<KeyFrame*, int>> counts;
  counts.reserve(distinct);
  for (const auto& entry : table) {
    if (entry.first != nullptr) counts.push_back(entry);
  }
  std::sort(counts.begin(), counts.end(),
            [](const auto& a, const auto& b) { return a.first->id() < b.first->id(); });

  // Edges need at least 15 shared points; keep the strongest one anyway so the graph stays
  // connected.
  constexpr int kMinWeight = 15;
  KeyFrame* strongest = nullptr;
  int strongest_weight = 0;
  std::map<KeyFrame*, int, KeyFrameIdLess> kept;
  for (const auto& [kf, w] : counts) {
    if (w > strongest_weight) {
      strongest_weight = w;
      strongest = kf;
    }
    if (w >= kMinWeight) kept.emplace_hint(kept.end(), kf, w);
  }
  if (kept.empty()) kept[strongest] = strongest_weight;

  // Links are symmetric: update the other side too.
  for (const auto& [kf, w] : connection_weights_) {
    if (!kept.contains(kf)) {
      kf->connection_weights_.erase(this);
      kf->ordered_connections_.erase(
          std::remove_if(kf->ordered_connections_.begin(), kf->ordered_connections_.end(),
                         [this](const auto& e) { return e.second == this; }),
          kf->ordered_connections_.end());
    }
  }
  ordered_connections_.clear();
  for (const auto& [kf, w] : kept) {
    ordered_connections_.emplace_back(w, kf);
    kf->connection_weights_[this] = w;
    auto& theirs = kf->ordered_connections_;
    theirs.erase(std::remove_if(theirs.begin(), theirs.end(),
                                [this](const auto& e) { return e.second == this; }),
                 theirs.end());
    // Still by weight, descending, ties in the order they came: after the last one of weight >= w
    // (as appending and a stable sort would place it, without the sort).
    const auto after =
        std::find_if(theirs.begin(), theirs.end(), [w = w](const auto& e) { return e.first < w; });
    theirs.emplace(after, w, this);
  }
  connection_weights_ = std::move(kept);
  std::stable_sort(ordered_connections_.begin(), ordered_connections_.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });

  if (first_connection_ && parent_ == nullptr && strongest != nullptr && strongest->id() < id_) {
    parent_ = strongest;
    strongest->children_.insert(this);
    first_connection_ = false;
  }
}

}  // namespace edgeslam
