#include "map/map.h"

#include <algorithm>
#include <stdexcept>

#include "map/map_participant.h"

namespace edgeslam {

Map::Map(std::uint8_t id_origin) : ids_(id_origin) {}

KeyFrame* Map::createKeyFrame(std::size_t frame_index, double timestamp,
                              std::shared_ptr<const FrameFeatures> features, const SE3d& T_cw,
                              KeyFrameId id) {
  if (id == kInvalidId) {
    id = ids_.next();
  } else {
    ids_.advancePast(id);
  }
  auto keyframe = std::make_unique<KeyFrame>(id, frame_index, timestamp, std::move(features), T_cw);
  KeyFrame* raw = keyframe.get();
  if (!keyframes_.emplace(id, std::move(keyframe)).second) {
    throw std::logic_error("Map: duplicate keyframe id");
  }
  if (origin_ == nullptr) origin_ = raw;
  record().keyFrameCreated(id);
  return raw;
}

MapPoint* Map::createMapPoint(const Eigen::Vector3d& position, KeyFrame* reference, MapPointId id) {
  if (id == kInvalidId) {
    id = ids_.next();
  } else {
    ids_.advancePast(id);
  }
  auto point = std::make_unique<MapPoint>(id, position, reference);
  MapPoint* raw = point.get();
  if (!points_.emplace(id, std::move(point)).second) {
    throw std::logic_error("Map: duplicate map point id");
  }
  record().pointCreated(id);
  return raw;
}

void Map::addObservation(MapPoint* point, KeyFrame* keyframe, std::size_t index) {
  if (point->isBad() || keyframe->isBad()) return;
  if (keyframe->points_[index] != nullptr && keyframe->points_[index] != point) {
    eraseObservation(keyframe->points_[index], keyframe);
  }
  const auto [it, inserted] =
      point->observations_.try_emplace(keyframe->id(), MapPoint::Observation{keyframe, index});
  if (!inserted) {
    if (it->second.index == index) return;
    keyframe->points_[it->second.index] = nullptr;
    it->second.index = index;
  } else {
    point->observation_weight_ += keyframe->features().hasDepth(index) ? 2 : 1;
  }
  keyframe->points_[index] = point;
  record().pointUpdated(point->id());
}

void Map::eraseObservation(MapPoint* point, KeyFrame* keyframe) {
  const auto it = point->observations_.find(keyframe->id());
  if (it == point->observations_.end()) return;
  const std::size_t index = it->second.index;
  point->observation_weight_ -= keyframe->features().hasDepth(index) ? 2 : 1;
  point->observations_.erase(it);
  if (keyframe->points_[index] == point) keyframe->points_[index] = nullptr;
  if (point->reference_keyframe_ == keyframe && !point->observations_.empty()) {
    point->reference_keyframe_ = point->observations_.begin()->second.keyframe;
  }
  if (point->observation_weight_ <= 2) {
    erasePoint(point);
  } else {
    record().pointUpdated(point->id());
  }
}

void Map::detachObservation(MapPoint* point, KeyFrame* keyframe) {
  const auto it = point->observations_.find(keyframe->id());
  if (it == point->observations_.end()) return;
  const std::size_t index = it->second.index;
  point->observation_weight_ -= keyframe->features().hasDepth(index) ? 2 : 1;
  point->observations_.erase(it);
  if (index < keyframe->points_.size() && keyframe->points_[index] == point) {
    keyframe->points_[index] = nullptr;
  }
  if (point->observations_.empty()) {
    erasePoint(point);
    return;
  }
  if (point->reference_keyframe_ == keyframe) {
    point->reference_keyframe_ = point->observations_.begin()->second.keyframe;
  }
  record().pointUpdated(point->id());
}

void Map::erasePoint(MapPoint* point) {
  if (point->bad_) return;
  point->bad_ = true;
  for (const auto& [id, obs] : point->observations_) {
    if (obs.keyframe->points_[obs.index] == point) obs.keyframe->points_[obs.index] = nullptr;
  }
  point->observations_.clear();
  point->observation_weight_ = 0;
  record().pointErased(point->id());
  auto node = points_.extract(point->id());
  if (!node.empty()) retire(std::move(node.mapped()));
}

void Map::replacePoint(MapPoint* old_point, MapPoint* replacement) {
  if (old_point == replacement || old_point->isBad() || replacement->isBad()) return;
  const auto observations = old_point->observations_;
  for (const auto& [id, obs] : observations) {
    if (replacement->observations_.contains(id)) {
      // Both seen in this keyframe: keep the replacement's keypoint, drop the old one's.
      continue;
    }
    obs.keyframe->points_[obs.index] = nullptr;
    addObservation(replacement, obs.keyframe, obs.index);
  }
  replacement->increaseVisible(old_point->visible_);
  replacement->increaseFound(old_point->found_);
  old_point->replaced_by_ = replacement;
  erasePoint(old_point);
  refreshPoint(replacement);
}

void Map::setPointPosition(MapPoint* point, const Eigen::Vector3d& position) {
  point->position_ = position;
  record().pointMoved(point->id());
}

void Map::relocatePoint(MapPoint* point, const Eigen::Vector3d& position) {
  point->position_ = position;
  if (!point->isBad()) point->updateNormalAndDepth();
  record().pointMoved(point->id());
}

void Map::refreshPoint(MapPoint* point) {
  if (point->isBad()) return;
  const cv::Mat before = point->descriptor_.clone();
  point->computeDistinctiveDescriptor();
  point->updateNormalAndDepth();
  // Normal and distance range follow from position and observations, which the other side has:
  // only a new representative descriptor makes this more than a move.
  const bool same_descriptor = !before.empty() && before.size() == point->descriptor_.size() &&
                               cv::norm(before, point->descriptor_, cv::NORM_HAMMING) == 0;
  if (same_descriptor) {
    record().pointMoved(point->id());
  } else {
    record().pointUpdated(point->id());
  }
}

void Map::setPointAppearance(MapPoint* point, const Eigen::Vector3d& normal,
                             const cv::Mat& descriptor, float min_distance, float max_distance) {
  point->normal_ = normal;
  point->descriptor_ = descriptor.clone();
  point->min_distance_ = min_distance;
  point->max_distance_ = max_distance;
  record().pointUpdated(point->id());
}

void Map::setKeyFramePose(KeyFrame* keyframe, const SE3d& T_cw) {
  keyframe->setPose(T_cw);
  record().keyFrameUpdated(keyframe->id());
}

void Map::updateConnections(KeyFrame* keyframe) {
  keyframe->updateConnections();
  record().keyFrameUpdated(keyframe->id());
}

void Map::unlinkConnections(KeyFrame* keyframe) {
  for (auto& [kf, w] : keyframe->connection_weights_) {
    kf->connection_weights_.erase(keyframe);
    auto& theirs = kf->ordered_connections_;
    theirs.erase(std::remove_if(theirs.begin(), theirs.end(),
                                [keyframe](const auto& e) { return e.second == keyframe; }),
                 theirs.end());
  }
  keyframe->connection_weights_.clear();
  keyframe->ordered_connections_.clear();
}

void Map::evictKeyFrame(KeyFrame* keyframe) {
  if (keyframe->bad_ || keyframe->evicted_) return;
  unlinkConnections(keyframe);
  for (std::size_t i = 0; i < keyframe->points_.size(); ++i) {
    // Not eraseObservation: a point the replica still sees once stays (the owner culls points).
    if (MapPoint* p = keyframe->points_[i]) detachObservation(p, keyframe);
  }
  keyframe->dropFeatures();
  keyframe->evicted_ = true;
  ++evicted_keyframes_;
}

void Map::restoreKeyFrame(KeyFrame* keyframe, std::shared_ptr<const FrameFeatures> features) {
  if (keyframe->bad_ || !keyframe->evicted_) return;
  keyframe->features_ = std::move(features);
  keyframe->points_.assign(keyframe->features_->size(), nullptr);
  keyframe->evicted_ = false;
  --evicted_keyframes_;
}

void Map::eraseKeyFrame(KeyFrame* keyframe, KeyFrame* covered_by) {
  if (keyframe->bad_ || keyframe == origin_ || keyframe->protected_from_culling_) return;
  if (covered_by != nullptr && covered_by != keyframe && !covered_by->bad_ &&
      covered_by != keyframe->parent_ && !hangsFrom(covered_by, keyframe)) {
    if (keyframe->parent_ != nullptr) keyframe->parent_->children_.erase(keyframe);
    keyframe->parent_ = covered_by;
    covered_by->children_.insert(keyframe);
  }
  unlinkConnections(keyframe);
  for (std::size_t i = 0; i < keyframe->points_.size(); ++i) {
    if (MapPoint* p = keyframe->points_[i]) eraseObservation(p, keyframe);
  }

  // Re-parent the children: repeatedly attach the child with the strongest covisibility link to any
  // keyframe already in the tree (the erased keyframe's parent to start with).
  KeyFrameSet candidates;
  if (keyframe->parent_ != nullptr) candidates.insert(keyframe->parent_);
  KeyFrameSet orphans = keyframe->children_;
  while (!orphans.empty()) {
    KeyFrame* best_child = nullptr;
    KeyFrame* best_parent = nullptr;
    int best_weight = -1;
    for (KeyFrame* child : orphans) {
      if (child->isBad()) continue;
      for (KeyFrame* candidate : candidates) {
        const int w = child->weight(candidate);
        if (w > best_weight) {
          best_weight = w;
          best_child = child;
          best_parent = candidate;
        }
      }
    }
    if (best_child == nullptr || best_weight <= 0) break;
    best_child->parent_ = best_parent;
    best_parent->children_.insert(best_child);
    candidates.insert(best_child);
    orphans.erase(best_child);
    record().keyFrameUpdated(best_child->id());
  }
  for (KeyFrame* orphan : orphans) {  // no covisible link left: hang them on the old parent
    orphan->parent_ = keyframe->parent_;
    if (keyframe->parent_ != nullptr) keyframe->parent_->children_.insert(orphan);
  }
  if (keyframe->parent_ != nullptr) {
    keyframe->parent_->children_.erase(keyframe);
    keyframe->T_cp_ = keyframe->T_cw_ * keyframe->parent_->T_wc_;
  }
  keyframe->children_.clear();
  keyframe->bad_ = true;
  if (keyframe->evicted_) --evicted_keyframes_;
  record().keyFrameErased(keyframe->id());
  auto node = keyframes_.extract(keyframe->id());
  if (!node.empty()) retire(std::move(node.mapped()));
}

bool Map::hangsFrom(const KeyFrame* keyframe, const KeyFrame* ancestor) const {
  std::size_t steps = 0;
  for (const KeyFrame* kf = keyframe; kf != nullptr && steps <= keyframes_.size();
       kf = kf->parent_, ++steps) {
    if (kf == ancestor) return true;
  }
  return false;
}

void Map::hangTreeFrom(KeyFrame* keyframe, KeyFrame* parent) {
  // The path to the old root, each link turned round from the root down.
  std::vector<KeyFrame*> path{keyframe};
  while (path.back()->parent_ != nullptr && path.size() <= keyframes_.size()) {
    path.push_back(path.back()->parent_);
  }
  for (std::size_t i = path.size() - 1; i > 0; --i) {
    KeyFrame* upper = path[i];
    KeyFrame* lower = path[i - 1];
    upper->children_.erase(lower);
    lower->parent_ = nullptr;
    upper->parent_ = lower;
    lower->children_.insert(upper);
    upper->first_connection_ = false;
    record().keyFrameUpdated(upper->id());
  }
  keyframe->parent_ = parent;
  keyframe->first_connection_ = false;
  parent->children_.insert(keyframe);
  record().keyFrameUpdated(keyframe->id());
}

void Map::addLoopEdge(KeyFrame* a, KeyFrame* b) {
  a->loop_edges_.insert(b);
  b->loop_edges_.insert(a);
  a->protected_from_culling_ = true;
  b->protected_from_culling_ = true;
  record().keyFrameUpdated(a->id());
  record().keyFrameUpdated(b->id());
}

void Map::clear() {
  for (auto& [id, p] : points_) {
    p->bad_ = true;
    retire(std::move(p));
  }
  for (auto& [id, kf] : keyframes_) {
    kf->bad_ = true;
    retire(std::move(kf));
  }
  points_.clear();
  keyframes_.clear();
  origin_ = nullptr;
  evicted_keyframes_ = 0;
  changes_.clear();
}

std::vector<KeyFrame*> Map::keyFrames() const {
  std::vector<KeyFrame*> out;
  out.reserve(keyframes_.size());
  for (const auto& [id, kf] : keyframes_) out.push_back(kf.get());
  std::sort(out.begin(), out.end(), KeyFrameIdLess{});
  return out;
}

std::vector<MapPoint*> Map::mapPoints() const {
  std::vector<MapPoint*> out;
  out.reserve(points_.size());
  for (const auto& [id, p] : points_) out.push_back(p.get());
  std::sort(out.begin(), out.end(), [](auto* a, auto* b) { return a->id() < b->id(); });
  return out;
}

std::vector<Eigen::Vector3d> Map::pointPositionSample(std::size_t max_count) const {
  std::vector<Eigen::Vector3d> out;
  if (max_count == 0 || points_.empty()) return out;
  const std::size_t stride = (points_.size() + max_count - 1) / max_count;
  out.reserve(std::min(max_count, points_.size()));
  std::size_t index = 0;
  for (const auto& [id, point] : points_) {
    if (index++ % stride == 0 && !point->isBad()) out.push_back(point->position());
  }
  return out;
}

KeyFrame* Map::keyFrame(KeyFrameId id) const {
  const auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : it->second.get();
}

MapPoint* Map::mapPoint(MapPointId id) const {
  const auto it = points_.find(id);
  return it == points_.end() ? nullptr : it->second.get();
}

void Map::retire(std::unique_ptr<MapPoint> point) {
  retired_points_.push_back({++erasures_, std::move(point)});
}

void Map::retire(std::unique_ptr<KeyFrame> keyframe) {
  keyframes_to_release_.push_back({++erasures_, keyframe.get()});
  erased_keyframes_.push_back(std::move(keyframe));
}

void Map::reclaim() {
  if (participants_.empty()) return;
  std::uint64_t safe = erasures_;
  for (const MapParticipant* participant : participants_) {
    safe = std::min(safe, participant->safe_through_);
  }
  // Both queues are in erasure order.
  while (!retired_points_.empty() && retired_points_.front().erasure <= safe) {
    retired_points_.pop_front();
    ++reclaimed_.points_freed;
  }
  while (!keyframes_to_release_.empty() && keyframes_to_release_.front().erasure <= safe) {
    KeyFrame* keyframe = keyframes_to_release_.front().keyframe;
    keyframe->dropFeatures();
    keyframe->place_.store(nullptr);
    keyframes_to_release_.pop_front();
    ++reclaimed_.keyframes_released;
  }
}

Map::Reclamation Map::reclamation() const {
  Reclamation out = reclaimed_;
  out.points_waiting = retired_points_.size();
  out.keyframes_waiting = keyframes_to_release_.size();
  out.participants = participants_.size();
  return out;
}

MapParticipant::MapParticipant(Map& map, std::string name) : map_(map), name_(std::move(name)) {
  MutexLock lock(map_.updateMutex());
  safe_through_ = map_.erasures_;
  map_.participants_.push_back(this);
}

MapParticipant::~MapParticipant() {
  MutexLock lock(map_.updateMutex());
  std::erase(map_.participants_, this);
  map_.reclaim();
}

void MapParticipant::quiescent(Map& map) {
  if (&map != &map_)
    throw std::logic_error("MapParticipant::quiescent: not this participant's map");
  safe_through_ = map.erasures_;
  map.reclaim();
}

MapChanges& Map::record() {
  if (recording_) return changes_;
  // Changes not recorded pile up here and are dropped now and then: emptying it on every change
  // rebuilt its seven sets each time, a fifth of creating a stored map's points (and of a client
  // applying a slice).
  MapChanges& c = ignored_changes_;
  if (c.points_created.size() + c.points_updated.size() + c.points_moved.size() +
          c.points_erased.size() + c.keyframes_created.size() + c.keyframes_updated.size() +
          c.keyframes_erased.size() >=
      4096) {
    c.clear();
  }
  return c;
}

MapChanges Map::takeChanges() {
  MapChanges out = std::move(changes_);
  changes_.clear();
  return out;
}

}  // namespace edgeslam
