#include "map/keyframe.h"

#include <algorithm>
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
  // Every observer of every point, then counted per keyframe in id order: a sort of one flat
  // vector instead of an ordered-map insert per observation (a client applies a slice by
  // re-linking a dozen keyframes of ~2000 points each).
  std::vector<KeyFrame*> observers;
  observers.reserve(points_.size() * 4);
  for (MapPoint* p : points_) {
    if (p == nullptr || p->isBad()) continue;
    for (const auto& [id, obs] : p->observations()) {
      if (obs.keyframe != this && !obs.keyframe->isBad()) observers.push_back(obs.keyframe);
    }
  }
  if (observers.empty()) return;
  std::sort(observers.begin(), observers.end(), KeyFrameIdLess{});
  std::vector<std::pair<KeyFrame*, int>> counts;
  for (KeyFrame* kf : observers) {
    if (counts.empty() || counts.back().first != kf) counts.emplace_back(kf, 0);
    ++counts.back().second;
  }

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
    if (w >= kMinWeight) kept[kf] = w;
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
  connection_weights_ = kept;
  ordered_connections_.clear();
  for (const auto& [kf, w] : kept) {
    ordered_connections_.emplace_back(w, kf);
    kf->connection_weights_[this] = w;
    auto& theirs = kf->ordered_connections_;
    theirs.erase(std::remove_if(theirs.begin(), theirs.end(),
                                [this](const auto& e) { return e.second == this; }),
                 theirs.end());
    theirs.emplace_back(w, this);
    std::stable_sort(theirs.begin(), theirs.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
  }
  std::stable_sort(ordered_connections_.begin(), ordered_connections_.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });

  if (first_connection_ && parent_ == nullptr && strongest != nullptr && strongest->id() < id_) {
    parent_ = strongest;
    strongest->children_.insert(this);
    first_connection_ = false;
  }
}

}  // namespace edgeslam
