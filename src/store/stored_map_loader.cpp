#include "store/stored_map_loader.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "map/map_replication.h"
#include "place/parallel_for.h"
#include "store/store_error.h"
#include "util/timing_stats.h"

namespace edgeslam {

namespace {

// A point record into a map that held nothing before the load: what upsertPointRecord does for a
// point the map does not have, without looking the point up or recording the change. (Its "made
// by this side after the sender's newest keyframe" exception cannot arise: every keyframe is the
// sender's.)
void createPointRecord(Map& map, const MapPointRecord& record,
                       std::vector<std::pair<KeyFrame*, std::size_t>>& observers)
    REQUIRES(map.updateMutex()) {
  observers.clear();
  for (const PointObservationRecord& obs : record.observations) {
    KeyFrame* kf = map.keyFrame(obs.keyframe);
    if (kf != nullptr && obs.keypoint_index < kf->size()) {
      observers.emplace_back(kf, obs.keypoint_index);
    }
  }
  if (observers.empty()) return;
  KeyFrame* reference = map.keyFrame(record.reference_keyframe);
  map.loadPoint({.id = record.id,
                 .position = record.position,
                 .reference = reference != nullptr ? reference : observers[0].first,
                 .observers = observers,
                 .normal = record.normal,
                 .descriptor = record.descriptor.data(),
                 .min_distance = record.min_distance,
                 .max_distance = record.max_distance});
}

// Files the keyframes (with `features`, one per record) and the points into `map`, then links
// the covisibility graph.
void fillMap(const StoredSession& session, std::vector<std::shared_ptr<FrameFeatures>>& features,
             Map& map, const Stopwatch& timer) {
  const double features_ms = timer.elapsedMs();
  MutexLock lock(map.updateMutex());
  // Into an empty map (a server resuming, `map info --load`) points are created without looking
  // for one of the same id first; a map with something in it has its points upserted.
  const bool fresh = map.keyFrameCount() == 0 && map.pointCount() == 0;
  map.setChangeRecording(false);
  try {
    KeyFrameId newest = kInvalidId;
    for (std::size_t i = 0; i < session.keyframes.size(); ++i) {
      const KeyFrameRecord& record = session.keyframes[i];
      // Linked to their points by the points' observations below.
      if (map.keyFrame(record.id) == nullptr) {
        map.createKeyFrame(record.frame_index, record.timestamp, std::move(features[i]),
                           record.T_cw, record.id);
      }
      map.ids().advancePast(record.id);
      newest = std::max(newest, record.id);
    }
    const double keyframes_ms = timer.elapsedMs();
    std::vector<std::pair<KeyFrame*, std::size_t>> observers;
    if (fresh) map.reservePoints(session.points.size());
    for (const MapPointRecord& record : session.points) {
      // (Point ids are unique in a session: a second record of one id fails to load.)
      if (fresh) {
        createPointRecord(map, record, observers);
      } else {
        upsertPointRecord(map, record, newest);
      }
      map.ids().advancePast(record.id);
    }
    const double points_ms = timer.elapsedMs();
    map.linkAllConnections();
    map.setChangeRecording(true);
    spdlog::debug(
        "stored session loaded: features {:.0f} ms, keyframes {:.0f} ms, points {:.0f} ms, "
        "covisibility {:.0f} ms",
        features_ms, keyframes_ms - features_ms, points_ms - keyframes_ms,
        timer.elapsedMs() - points_ms);
  } catch (const std::logic_error& e) {  // records that contradict themselves
    map.setChangeRecording(true);
    throw StoreError(std::string("stored session does not load: ") + e.what());
  }
}

template <typename Session>
void loadSession(Session& session, Map& map) {
  // The keyframes' features (the records' arrays, keypoint grids) are independent of each other
  // and of the map: built on every core first, then filed into the map in order.
  Stopwatch timer;
  std::vector<std::shared_ptr<FrameFeatures>> features(session.keyframes.size());
  try {
    parallelFor(session.keyframes.size(), hardwareThreads(), [&](std::size_t i, int) {
      if constexpr (std::is_const_v<Session>) {
        features[i] = featuresFromRecord(session.keyframes[i].features, session.info.camera);
      } else {
        features[i] =
            featuresFromRecord(std::move(session.keyframes[i].features), session.info.camera);
      }
    });
  } catch (const std::invalid_argument& e) {
    throw StoreError(std::string("stored session does not load: ") + e.what());
  }
  fillMap(session, features, map, timer);
}

}  // namespace

void loadStoredSession(const StoredSession& session, Map& map) {
  loadSession(session, map);
}

void loadStoredSessionTakingFeatures(StoredSession& session, Map& map) {
  loadSession(session, map);
}

AttachedPlaces attachStoredPlaces(const StoredSession& session, Map& map,
                                  const Vocabulary& vocabulary, std::uint64_t checksum,
                                  int direct_index_depth) {
  AttachedPlaces out;
  MutexLock lock(map.updateMutex());
  for (const KeyFramePlaceRecord& record : session.places) {
    if (record.vocabulary != checksum || record.direct_index_depth != direct_index_depth) continue;
    KeyFrame* keyframe = map.keyFrame(record.keyframe);
    if (keyframe == nullptr || keyframe->isBad()) continue;
    for (const BowEntry& e : record.bow) {
      if (e.word >= vocabulary.wordCount()) {
        throw StoreError("damaged bag of words of keyframe " + std::to_string(record.keyframe) +
                         ": word " + std::to_string(e.word) + " of " +
                         std::to_string(vocabulary.wordCount()));
      }
    }
    for (std::size_t i = 0; i < record.features.size(); ++i) {
      if (record.features.node(i) >= vocabulary.nodeCount()) {
        throw StoreError("damaged direct index of keyframe " + std::to_string(record.keyframe) +
                         ": node " + std::to_string(record.features.node(i)));
      }
      for (const int index : record.features.features(i)) {
        if (index < 0 || static_cast<std::size_t>(index) >= keyframe->size()) {
          throw StoreError("damaged direct index of keyframe " + std::to_string(record.keyframe) +
                           ": feature " + std::to_string(index));
        }
      }
    }
    auto place = std::make_shared<KeyFramePlace>();
    place->bow = record.bow;
    place->features = record.features;
    place->direct_index_depth = direct_index_depth;
    place->vocabulary = &vocabulary;
    keyframe->setPlace(std::move(place));
    ++out.attached;
  }
  for (KeyFrame* keyframe : map.keyFrames()) {
    if (!keyframe->isBad() && keyframe->place() == nullptr) out.missing.push_back(keyframe->id());
  }
  return out;
}

std::size_t describeKeyFrames(Map& map, const Vocabulary& vocabulary, int direct_index_depth) {
  std::vector<KeyFrame*> keyframes;
  {
    MutexLock lock(map.updateMutex());
    for (KeyFrame* keyframe : map.keyFrames()) {
      const auto place = keyframe->place();
      if (keyframe->isBad() || (place != nullptr && place->vocabulary == &vocabulary &&
                                place->direct_index_depth == direct_index_depth)) {
        continue;
      }
      keyframes.push_back(keyframe);
    }
  }
  // The features never change: no lock needed (as LocalMapper::describe).
  const int levels_up = std::max(0, vocabulary.levels() - direct_index_depth);
  for (KeyFrame* keyframe : keyframes) {
    auto place = std::make_shared<KeyFramePlace>();
    place->direct_index_depth = direct_index_depth;
    place->vocabulary = &vocabulary;
    vocabulary.transform(keyframe->features().descriptors, levels_up, place->bow, place->features);
    keyframe->setPlace(std::move(place));
  }
  return keyframes.size();
}

StoredSession* latestSessionWithKeyFrames(StoredMap& map) {
  for (auto it = map.sessions.rbegin(); it != map.sessions.rend(); ++it) {
    if (!it->keyframes.empty()) return &*it;
  }
  return nullptr;
}

}  // namespace edgeslam
