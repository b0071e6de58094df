#include "store/stored_map_loader.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "map/map_replication.h"
#include "store/store_error.h"

namespace edgeslam {

void loadStoredSession(const StoredSession& session, Map& map) {
  std::lock_guard lock(map.updateMutex());
  map.setChangeRecording(false);
  try {
    KeyFrameId newest = kInvalidId;
    for (const KeyFrameRecord& record : session.keyframes) {
      KeyFrameRecord without_points = record;
      without_points.point_ids.clear();  // linked by the points' observations below
      insertKeyFrameRecord(map, without_points, session.info.camera);
      map.ids().advancePast(record.id);
      newest = std::max(newest, record.id);
    }
    for (const MapPointRecord& record : session.points) {
      upsertPointRecord(map, record, newest);
      map.ids().advancePast(record.id);
    }
    for (KeyFrame* keyframe : map.keyFrames()) map.updateConnections(keyframe);
  } catch (const std::invalid_argument& e) {
    map.setChangeRecording(true);
    throw StoreError(std::string("stored session does not load: ") + e.what());
  }
  map.setChangeRecording(true);
}

AttachedPlaces attachStoredPlaces(const StoredSession& session, Map& map,
                                  const Vocabulary& vocabulary, std::uint64_t checksum,
                                  int direct_index_depth) {
  AttachedPlaces out;
  std::lock_guard lock(map.updateMutex());
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
    std::lock_guard lock(map.updateMutex());
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

}  // namespace edgeslam
