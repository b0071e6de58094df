#pragma once
// One client's session on the edge: the global map, fed by the client's keyframe uploads and kept
// by local mapping on its own thread; after each mapped keyframe, what changed goes back to the
// client as a map slice.
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include "edge/local_mapper.h"
#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_records.h"
#include "map/sensor.h"

namespace edgeslam {

struct EdgeMapSessionOptions {
  LocalMapperOptions mapper;
  bool threaded = true;  // false: map each keyframe inside onKeyFrame (deterministic tests)
};

struct EdgeMapSessionStats {
  std::uint64_t uploads = 0;
  std::uint64_t slices = 0;
  std::uint64_t keyframes = 0;
  std::uint64_t map_points = 0;
};

class EdgeMapSession {
 public:
  using Publish = std::function<void(MapSlice)>;

  EdgeMapSession(const PinholeCamera& camera, Sensor sensor, EdgeMapSessionOptions options,
                 Publish publish);
  ~EdgeMapSession();
  EdgeMapSession(const EdgeMapSession&) = delete;
  EdgeMapSession& operator=(const EdgeMapSession&) = delete;

  // Adds the keyframe and its new points to the global map and queues it for mapping. Throws
  // std::invalid_argument for records that contradict themselves.
  void onKeyFrame(const KeyFrameUpload& upload);
  // Waits until every queued keyframe is mapped and its slice published.
  void finish();
  void stop();

  EdgeMapSessionStats stats() const;
  Map& map() { return map_; }

 private:
  void publishSlice(KeyFrame* mapped);

  PinholeCamera camera_;
  Map map_;
  std::unique_ptr<LocalMapper> mapper_;
  Publish publish_;
  bool threaded_;

  mutable std::mutex state_mutex_;  // guards the fields below (not the map)
  std::uint64_t slice_sequence_ = 0;
  std::uint64_t last_upload_sequence_ = 0;
  KeyFrameId newest_keyframe_ = kInvalidId;
  EdgeMapSessionStats stats_;
};

}  // namespace edgeslam
