#pragma once
// Where edge maps persist: named maps, each made of the sessions that wrote into it. A session's
// keyframes and points keep the ids they had in its map (ids are unique within a session only);
// each session's map is in its own frame until maps are merged.
//
// The interface is what a server-class backend (PostgreSQL, for several edge nodes) implements
// next to the embedded SQLite one (sqlite_map_store.h).
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "map/map_records.h"
#include "map/sensor.h"
#include "place/bow_vector.h"
#include "place/feature_vector.h"

namespace edgeslam {

struct MapSummary {
  std::string name;
  std::uint64_t keyframes = 0;
  std::uint64_t points = 0;
  std::uint64_t sessions = 0;
  // A session measured depth (RGB-D or stereo): the map has a metric scale. Monocular sessions
  // merged into such a map took its scale; a map of monocular sessions only has none.
  bool metric = false;
  std::uint64_t bytes = 0;  // payload bytes of the map's rows (blobs and values), roughly its share
  double created = 0.0;     // Unix seconds
  double updated = 0.0;
  // Axis-aligned bounds of the points (zero when the map has none).
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d extent_max = Eigen::Vector3d::Zero();
};

struct StoredSessionInfo {
  std::string client;
  PinholeCamera camera;
  Sensor sensor = Sensor::kMonocular;
};

using StoreSessionId = std::int64_t;

// A keyframe's bag of words and direct index (KeyFramePlace) as a vocabulary made them: stored so
// that a map read back need not compute them again (~1.8 ms a keyframe), and used only with the
// same vocabulary at the same direct-index depth.
struct KeyFramePlaceRecord {
  KeyFrameId keyframe = kInvalidId;
  std::uint64_t vocabulary = 0;  // Vocabulary::checksum() of the one that made it
  int direct_index_depth = 0;
  BowVector bow;
  FeatureVector features;
};

// One transaction's worth of changes of one session's map.
struct MapStoreBatch {
  bool cleared = false;  // the session's map was emptied (a failed start) before what follows
  std::vector<KeyFrameRecord> keyframes;  // new keyframes (whole records; point_ids unused)
  std::vector<KeyFramePoseRecord> poses;  // keyframes already stored whose pose changed
  std::vector<MapPointRecord> points;     // new or changed points, whole
  // Stored points that only moved: position, normal and distance range (the rest is unchanged).
  std::vector<MapPointRecord> points_moved;
  std::vector<MapPointId> points_erased;
  std::vector<KeyFrameId> keyframes_erased;
  std::vector<MaskRecord> masks;            // semantic labels of keyframes
  std::vector<KeyFramePlaceRecord> places;  // of keyframes stored (now or before)
  bool empty() const {
    return !cleared && keyframes.empty() && poses.empty() && points.empty() &&
           points_moved.empty() && points_erased.empty() && keyframes_erased.empty() &&
           masks.empty() && places.empty();
  }
};

// A route on a map, for navigation: checkpoints in the map's frame, in the order they are to be
// reached (`edgeslam route`).
struct RouteRecord {
  std::string name;
  // What the checkpoints were made from, for people ("keyframes of session 1, frames 500-999").
  std::string source;
  double spacing_m = 0.0;  // along the path between checkpoints (0: positions given one by one)
  Eigen::Vector3d up = -Eigen::Vector3d::UnitY();  // the map's up, unit: turns are about it
  std::vector<Eigen::Vector3d> checkpoints;
  double created = 0.0;  // Unix seconds
};

struct StoredSession {
  StoreSessionId id = 0;
  StoredSessionInfo info;
  double started = 0.0;
  double ended = 0.0;                     // 0 while open (or when the server died)
  std::vector<KeyFrameRecord> keyframes;  // by id; point_ids filled from the observations
  std::vector<MapPointRecord> points;     // by id
  std::vector<MaskRecord> masks;
  std::vector<KeyFramePlaceRecord> places;  // by keyframe; none in a store of schema version 1
};

struct StoredMap {
  std::string name;
  std::vector<StoredSession> sessions;
};

class MapStore {
 public:
  virtual ~MapStore() = default;

  // Where it is, for messages ("PATH/maps.sqlite").
  virtual std::string location() const = 0;
  virtual std::vector<MapSummary> listMaps() = 0;
  virtual std::optional<MapSummary> mapInfo(const std::string& name) = 0;
  virtual std::optional<StoredMap> loadMap(const std::string& name) = 0;
  // Creates the map when it does not exist yet. Throws StoreError.
  virtual StoreSessionId beginSession(const std::string& map, const StoredSessionInfo& info) = 0;
  // In one transaction; throws StoreError, leaving the store as it was.
  virtual void write(StoreSessionId session, const MapStoreBatch& batch) = 0;
  virtual void endSession(StoreSessionId session) = 0;
  // A stored session written to again (a server resuming it after a restart): open again.
  virtual void resumeSession(StoreSessionId session) = 0;
  virtual bool removeMap(const std::string& name) = 0;
  // Routes of a map (saved with it, removed with it). saveRoute replaces a route of that name;
  // throws StoreError when the map does not exist.
  virtual void saveRoute(const std::string& map, const RouteRecord& route) = 0;
  virtual std::vector<RouteRecord> listRoutes(const std::string& map) = 0;
  virtual bool removeRoute(const std::string& map, const std::string& route) = 0;
};

enum class MapStoreAccess {
  kRead,   // list, info, export: an existing store, read-only, beside a server writing to it
  kEdit,   // rm: an existing store, locked (no server may be writing to it)
  kServe,  // server, run: created when absent, locked while this process lives
};

// The embedded default: `directory`/maps.sqlite (and maps.lock, held by the one process that may
// write). Throws StoreError with a one-line message naming the file: missing, corrupt, truncated,
// newer schema, locked by another process, read-only.
std::unique_ptr<MapStore> openMapStore(const std::filesystem::path& directory,
                                       MapStoreAccess access);

}  // namespace edgeslam
