#pragma once
// A map shaped like a corridor walk: keyframe k sees points [k*step, k*step + span), so each
// keyframe shares span - step points with the next, span - 2 step with the one after, and so on
// (links under 15 shared points are not kept). Known covisibility for window and eviction tests.
#include <memory>
#include <vector>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_replication.h"
#include "map/synthetic_views.h"

namespace edgeslam::test {

inline std::shared_ptr<FrameFeatures> corridorFeatures(const PinholeCamera& camera, int count) {
  auto features = std::make_shared<FrameFeatures>();
  for (int i = 0; i < count; ++i) {
    features->keypoints.emplace_back(static_cast<float>(20 + 12 * (i % 50)),
                                     static_cast<float>(20 + 12 * (i / 50)), 31.f, 0.f, 0.f, 0);
  }
  features->descriptors = cv::Mat(count, 32, CV_8UC1);
  for (int i = 0; i < count; ++i) features->descriptors.row(i).setTo(cv::Scalar(i % 256));
  features->grid = FeatureGrid(camera.undistortedBounds(), features->keypoints);
  return features;
}

struct Corridor {
  static constexpr int kSpan = 40;
  static constexpr int kStep = 10;

  PinholeCamera camera = syntheticCamera();
  Map map;
  std::vector<KeyFrame*> keyframes;
  std::vector<MapPoint*> points;  // by scene index

  // Keyframe ids carry `origin` (1: made by client 1, as on the edge).
  explicit Corridor(int count, std::uint8_t origin = 1) : map(origin) {
    for (int k = 0; k < count; ++k) addKeyFrame(k * kStep);
    map.takeChanges();
  }

  // A new keyframe seeing points [first, first + span) (a revisit when they exist already), with
  // its covisibility links on both sides.
  KeyFrame* addKeyFrame(int first) REQUIRES(map.updateMutex()) {
    const std::size_t end = static_cast<std::size_t>(first + kSpan);
    if (points.size() < end) points.resize(end, nullptr);
    const double x = 0.1 * first / kStep;
    const SE3d T_cw(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-x, 0, 0));
    KeyFrame* kf = map.createKeyFrame(keyframes.size(), 0.1 * static_cast<double>(keyframes.size()),
                                      corridorFeatures(camera, kSpan), T_cw);
    for (int i = 0; i < kSpan; ++i) {
      MapPoint*& p = points[static_cast<std::size_t>(first + i)];
      if (p == nullptr) p = map.createMapPoint(Eigen::Vector3d(x + 0.01 * i, 0.0, 3.0), kf);
      map.addObservation(p, kf, static_cast<std::size_t>(i));
    }
    map.updateConnections(kf);
    keyframes.push_back(kf);
    return kf;
  }

  // Point of scene index `i` (nullptr when erased).
  MapPoint* point(int i) const {
    MapPoint* p = points[static_cast<std::size_t>(i)];
    return p != nullptr && !p->isBad() ? p : nullptr;
  }
  KeyFrameId id(int k) const { return keyframes[static_cast<std::size_t>(k)]->id(); }

  // A replica holding everything, built from records as the client would receive them.
  void replicateInto(Map& replica) const REQUIRES(map.updateMutex(), replica.updateMutex()) {
    for (KeyFrame* kf : keyframes) insertKeyFrameRecord(replica, keyFrameRecord(*kf), camera);
    for (MapPoint* p : map.mapPoints()) {
      upsertPointRecord(replica, mapPointRecord(*p), keyframes.back()->id());
    }
    for (KeyFrame* kf : replica.keyFrames()) replica.updateConnections(kf);
    replica.takeChanges();
  }
};

}  // namespace edgeslam::test
