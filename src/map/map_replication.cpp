#include "map/map_replication.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace edgeslam {

KeyFrameFeaturesRecord featuresRecord(const FrameFeatures& features) {
  KeyFrameFeaturesRecord record;
  record.keypoints = features.keypoints;
  record.descriptors = features.descriptors.clone();
  record.depth = features.depth;
  record.right_u = features.right_u;
  record.pyramid_levels = features.scales.numLevels();
  record.scale_factor = features.scales.scaleFactor();
  record.bf = features.bf;
  return record;
}

namespace {

// Throws std::invalid_argument when the arrays disagree.
void checkFeaturesRecord(const KeyFrameFeaturesRecord& record) {
  const std::size_t n = record.keypoints.size();
  if (static_cast<std::size_t>(record.descriptors.rows) != n ||
      (n > 0 && (record.descriptors.cols != 32 || record.descriptors.type() != CV_8U))) {
    throw std::invalid_argument(
        "keyframe features: descriptors must be one 32-byte row per keypoint");
  }
  if ((!record.depth.empty() && record.depth.size() != n) ||
      (!record.right_u.empty() && record.right_u.size() != n)) {
    throw std::invalid_argument(
        "keyframe features: depth / right_u must have one value per keypoint");
  }
  for (const cv::KeyPoint& kp : record.keypoints) {
    if (kp.octave < 0 || kp.octave >= record.pyramid_levels) {
      throw std::invalid_argument("keyframe features: keypoint octave outside the pyramid");
    }
  }
}

std::shared_ptr<FrameFeatures> featuresWithGrid(std::shared_ptr<FrameFeatures> features,
                                                const KeyFrameFeaturesRecord& record,
                                                const PinholeCamera& camera) {
  features->scales = ScaleLevels(record.pyramid_levels, record.scale_factor);
  features->bf = record.bf;
  features->grid = FeatureGrid(camera.undistortedBounds(), features->keypoints);
  return features;
}

}  // namespace

std::shared_ptr<FrameFeatures> featuresFromRecord(const KeyFrameFeaturesRecord& record,
                                                  const PinholeCamera& camera) {
  checkFeaturesRecord(record);
  auto features = std::make_shared<FrameFeatures>();
  features->keypoints = record.keypoints;
  features->descriptors = record.descriptors.clone();
  features->depth = record.depth;
  features->right_u = record.right_u;
  return featuresWithGrid(std::move(features), record, camera);
}

std::shared_ptr<FrameFeatures> featuresFromRecord(KeyFrameFeaturesRecord&& record,
                                                  const PinholeCamera& camera) {
  checkFeaturesRecord(record);
  auto features = std::make_shared<FrameFeatures>();
  features->keypoints = std::move(record.keypoints);
  // The record's own matrix (not shared: taken, the record keeps none).
  features->descriptors = record.descriptors.u != nullptr && record.descriptors.u->refcount == 1
                              ? record.descriptors
                              : record.descriptors.clone();
  record.descriptors.release();
  features->depth = std::move(record.depth);
  features->right_u = std::move(record.right_u);
  return featuresWithGrid(std::move(features), record, camera);
}

KeyFrameRecord keyFrameRecord(const KeyFrame& keyframe) {
  KeyFrameRecord record;
  record.id = keyframe.id();
  record.frame_index = keyframe.frameIndex();
  record.timestamp = keyframe.timestamp();
  record.T_cw = keyframe.pose();
  record.parent = keyframe.parent() != nullptr ? keyframe.parent()->id() : kInvalidId;
  record.features = featuresRecord(keyframe.features());
  record.point_ids.assign(keyframe.size(), kInvalidId);
  for (std::size_t i = 0; i < keyframe.size(); ++i) {
    const MapPoint* p = keyframe.point(i);
    if (p != nullptr && !p->isBad()) record.point_ids[i] = p->id();
  }
  return record;
}

MapPointRecord mapPointRecord(const MapPoint& point) {
  MapPointRecord record;
  record.id = point.id();
  record.position = point.position();
  record.normal = point.normal();
  if (point.descriptor().total() == record.descriptor.size()) {
    std::memcpy(record.descriptor.data(), point.descriptor().data, record.descriptor.size());
  }
  record.min_distance = point.baseMinDistance();
  record.max_distance = point.baseMaxDistance();
  record.reference_keyframe =
      point.referenceKeyFrame() != nullptr ? point.referenceKeyFrame()->id() : kInvalidId;
  record.observations.reserve(point.observations().size());
  for (const auto& [id, obs] : point.observations()) {
    record.observations.push_back({id, static_cast<std::uint32_t>(obs.index)});
  }
  return record;
}

KeyFramePoseRecord keyFramePoseRecord(const KeyFrame& keyframe) {
  return {keyframe.id(), keyframe.pose(),
          keyframe.parent() != nullptr ? keyframe.parent()->id() : kInvalidId};
}

KeyFrame* insertKeyFrameRecord(Map& map, const KeyFrameRecord& record,
                               const PinholeCamera& camera) {
  KeyFrame* keyframe = map.keyFrame(record.id);
  if (keyframe != nullptr && !keyframe->isEvicted()) return keyframe;
  auto features = featuresFromRecord(record.features, camera);
  if (!record.point_ids.empty() && record.point_ids.size() != features->size()) {
    throw std::invalid_argument("keyframe record: point ids must be one per keypoint");
  }
  if (keyframe != nullptr) {  // back in the part of the map the replica holds
    map.restoreKeyFrame(keyframe, std::move(features));
    map.setKeyFramePose(keyframe, record.T_cw);
  } else {
    keyframe = map.createKeyFrame(record.frame_index, record.timestamp, std::move(features),
                                  record.T_cw, record.id);
  }
  for (std::size_t i = 0; i < record.point_ids.size(); ++i) {
    if (record.point_ids[i] == kInvalidId) continue;
    MapPoint* p = map.mapPoint(record.point_ids[i]);
    if (p != nullptr && !p->isBad()) map.addObservation(p, keyframe, i);
  }
  return keyframe;
}

namespace {

// A point this side made in a keyframe the sender had not received yet (a monocular client
// triangulating with an older keyframe): the sender's records cannot know it, so they do not take
// its keypoints; the sender settles the clash when that keyframe arrives there
// (resolveUploadedPointConflicts).
bool unknownToSender(const MapPoint* point, KeyFrameId newest_known_to_sender) {
  const KeyFrameId born = point->firstKeyFrameId();
  return born != kInvalidId && idOrigin(born) == idOrigin(newest_known_to_sender) &&
         born > newest_known_to_sender;
}

}  // namespace

MapPoint* upsertPointRecord(Map& map, const MapPointRecord& record,
                            KeyFrameId newest_known_to_sender) {
  std::vector<std::pair<KeyFrame*, std::size_t>> observers;
  for (const PointObservationRecord& obs : record.observations) {
    KeyFrame* kf = map.keyFrame(obs.keyframe);
    // size() is 0 for an evicted keyframe: observations there are not held.
    if (kf == nullptr || obs.keypoint_index >= kf->size()) continue;
    const MapPoint* there = kf->point(obs.keypoint_index);
    if (there != nullptr && there->id() != record.id && !there->isBad() &&
        unknownToSender(there, newest_known_to_sender)) {
      continue;
    }
    observers.emplace_back(kf, obs.keypoint_index);
  }
  MapPoint* point = map.mapPoint(record.id);
  std::vector<KeyFrame*> dropped;
  if (point == nullptr) {
    if (observers.empty()) return nullptr;
    KeyFrame* reference = map.keyFrame(record.reference_keyframe);
    if (reference != nullptr && reference->isEvicted()) reference = nullptr;
    point = map.createMapPoint(record.position,
                               reference != nullptr ? reference : observers[0].first, record.id);
  } else {
    map.setPointPosition(point, record.position);
    // Observations the other side dropped (outliers, culled keyframes) go here too.
    for (const auto& [id, obs] : point->observations()) {
      KeyFrame* const observer = obs.keyframe;  // a lambda cannot capture a binding (clang 14)
      const bool kept = std::any_of(observers.begin(), observers.end(),
                                    [&](const auto& o) { return o.first == observer; });
      // Edge-made keyframes (origin 0) are always known to the edge; a client's are known up
      // to the newest one the edge had received.
      const bool sender_knew =
          idOrigin(id) == 0 ||
          (idOrigin(id) == idOrigin(newest_known_to_sender) && id <= newest_known_to_sender);
      if (!kept && sender_knew) dropped.push_back(obs.keyframe);
    }
  }
  // New observations first: dropping first could leave too few and erase the point.
  // (eraseObservation culls a point left with two observations or fewer even where the sender
  // keeps it: detaching instead, to mirror the sender exactly, kept weak points that made KITTI
  // edge tracking get lost in 5 runs out of 6.)
  for (const auto& [kf, index] : observers) map.addObservation(point, kf, index);
  for (KeyFrame* kf : dropped) {
    if (point->isBad()) break;
    map.eraseObservation(point, kf);
  }
  if (point->isBad()) return nullptr;
  const cv::Mat descriptor(1, 32, CV_8U, const_cast<std::uint8_t*>(record.descriptor.data()));
  map.setPointAppearance(point, record.normal, descriptor, record.min_distance,
                         record.max_distance);
  return point;
}

std::optional<UploadedPointConflict> insertUploadedPoint(Map& map, const MapPointRecord& record,
                                                         KeyFrameId uploaded_keyframe) {
  MapPointRecord applied = record;
  MapPoint* occupant = nullptr;
  bool dropped = false;
  std::erase_if(applied.observations,
                [&](const PointObservationRecord& obs) REQUIRES(map.updateMutex()) {
                  if (obs.keyframe == uploaded_keyframe) return false;
                  const KeyFrame* kf = map.keyFrame(obs.keyframe);
                  // A later keyframe of the sender (not here yet) links the point when it arrives.
                  if (kf == nullptr && idOrigin(obs.keyframe) == idOrigin(uploaded_keyframe) &&
                      obs.keyframe > uploaded_keyframe) {
                    return false;
                  }
                  if (kf == nullptr || obs.keypoint_index >= kf->size()) {
                    dropped = true;
                    return true;
                  }
                  MapPoint* there = kf->point(obs.keypoint_index);
                  if (there != nullptr && !there->isBad() && there->id() != record.id) {
                    if (occupant == nullptr) occupant = there;
                    dropped = true;
                    return true;
                  }
                  return false;
                });
  MapPoint* point = upsertPointRecord(map, applied, uploaded_keyframe);
  if (point == nullptr) return std::nullopt;
  map.refreshPoint(point);
  if (!dropped) return std::nullopt;
  return UploadedPointConflict{point, occupant};
}

namespace {

// Records the point as updated, so that the next slice carries all of it (observations too): the
// client's copy differs in more than the changes recorded here show.
void sendAgain(Map& map, MapPoint* point) REQUIRES(map.updateMutex()) {
  map.setPointAppearance(point, point->normal(), point->descriptor(), point->baseMinDistance(),
                         point->baseMaxDistance());
}

}  // namespace

void resolveUploadedPointConflicts(Map& map, const std::vector<UploadedPointConflict>& conflicts) {
  for (const UploadedPointConflict& c : conflicts) {
    if (c.point->isBad()) continue;
    if (c.occupant != nullptr && !c.occupant->isBad()) {
      map.replacePoint(c.point, c.occupant);
      // The client may lack the occupant's observation on the contested keypoint (its own point
      // held it there, upsertPointRecord), even where the merge itself changes nothing.
      if (!c.occupant->isBad()) sendAgain(map, c.occupant);
    } else if (c.point->observationCount() <= 2) {
      map.erasePoint(c.point);
    } else {
      sendAgain(map, c.point);
    }
  }
}

namespace {

Eigen::Vector3d backProject(const cv::KeyPoint& keypoint, float depth, const SE3d& T_wc,
                            const PinholeCamera& camera) {
  return T_wc * (camera.unproject({keypoint.pt.x, keypoint.pt.y}) * static_cast<double>(depth));
}

}  // namespace

bool isDepthBackProjection(const MapPoint& point, const KeyFrame& keyframe,
                           const PinholeCamera& camera) {
  constexpr double kTolerance = 1e-4;  // m; the wire's keypoints and depths are finer than this
  const auto& observations = point.observations();
  if (observations.empty()) return false;
  const auto& first = observations.begin()->second;
  if (first.keyframe != &keyframe) return false;
  const FrameFeatures& features = keyframe.features();
  if (first.index >= features.size() || !features.hasDepth(first.index)) return false;
  const Eigen::Vector3d expected = backProject(
      features.keypoints[first.index], features.depth[first.index], keyframe.poseInverse(), camera);
  return (expected - point.position()).norm() <= kTolerance;
}

void rebuildPositionsFromDepth(std::vector<MapPointRecord>& points, const KeyFrameRecord& keyframe,
                               const PinholeCamera& camera) {
  const KeyFrameFeaturesRecord& features = keyframe.features;
  const SE3d T_wc = keyframe.T_cw.inverse();
  for (MapPointRecord& point : points) {
    if (!point.position_from_depth) continue;
    const auto fail = [&](const std::string& why) {
      throw std::invalid_argument("point " + std::to_string(point.id) +
                                  ": position from depth, but " + why);
    };
    if (point.observations.empty()) fail("it has no observation");
    const PointObservationRecord& first = point.observations.front();
    if (first.keyframe != keyframe.id) fail("its first observation is in another keyframe");
    if (first.keypoint_index >= features.keypoints.size()) fail("its keypoint does not exist");
    if (first.keypoint_index >= features.depth.size() ||
        !(features.depth[first.keypoint_index] > 0.f)) {
      fail("its keypoint has no depth");
    }
    point.position = backProject(features.keypoints[first.keypoint_index],
                                 features.depth[first.keypoint_index], T_wc, camera);
  }
}

}  // namespace edgeslam
