#include "store/sqlite_map_store.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <sqlite3.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>

#include "store/record_blobs.h"
#include "store/store_error.h"
#include "store/store_schema.h"
#include "util/timing_stats.h"

namespace edgeslam {
namespace {

double nowSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// Ids are unsigned 64-bit with the creator in the top byte; SQLite integers are signed: the bits
// are kept as they are.
std::int64_t toSql(std::uint64_t id) {
  return static_cast<std::int64_t>(id);
}
std::uint64_t fromSql(std::int64_t value) {
  return static_cast<std::uint64_t>(value);
}

Sensor sensorFromName(const std::string& name) {
  for (const Sensor s : {Sensor::kMonocular, Sensor::kRgbd, Sensor::kStereo}) {
    if (name == toString(s)) return s;
  }
  throw StoreError("unknown sensor '" + name + "' in the map store");
}

std::string withFile(const SqliteDatabase& db, const std::exception& e) {
  const std::string message = e.what();
  const std::string file = db.file().string();
  return message.starts_with(file) ? message : file + ": " + message;
}

}  // namespace

struct SqliteMapStore::Statements {
  explicit Statements(SqliteDatabase& db)
      : map_id(db, "SELECT id FROM maps WHERE name = ?"),
        insert_map(db, "INSERT INTO maps(name, created, updated) VALUES(?, ?, ?)"),
        touch_map(db,
                  "UPDATE maps SET updated = ? WHERE id = (SELECT map_id FROM sessions WHERE "
                  "id = ?)"),
        insert_session(db,
                       "INSERT INTO sessions(map_id, client, sensor, width, height, fx, fy, cx, "
                       "cy, k1, k2, p1, p2, k3, baseline_m, depth_factor, fps, started) "
                       "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"),
        end_session(db, "UPDATE sessions SET ended = ? WHERE id = ?"),
        clear_keyframes(db, "DELETE FROM keyframes WHERE session_id = ?"),
        clear_points(db, "DELETE FROM points WHERE session_id = ?"),
        clear_masks(db, "DELETE FROM masks WHERE session_id = ?"),
        insert_keyframe(db,
                        "INSERT OR REPLACE INTO keyframes(session_id, id, frame_index, timestamp, "
                        "pose, parent, pyramid_levels, scale_factor, bf, keypoints, descriptors, "
                        "depth, right_u) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"),
        update_pose(db,
                    "UPDATE keyframes SET pose = ?, parent = ? WHERE session_id = ? AND id = ?"),
        erase_keyframe(db, "DELETE FROM keyframes WHERE session_id = ? AND id = ?"),
        erase_mask(db, "DELETE FROM masks WHERE session_id = ? AND keyframe = ?"),
        insert_point(db,
                     "INSERT OR REPLACE INTO points(session_id, id, x, y, z, nx, ny, nz, "
                     "descriptor, min_distance, max_distance, reference, observations) "
                     "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)"),
        move_point(db,
                   "UPDATE points SET x = ?, y = ?, z = ?, nx = ?, ny = ?, nz = ?, min_distance = "
                   "?, max_distance = ? WHERE session_id = ? AND id = ?"),
        erase_point(db, "DELETE FROM points WHERE session_id = ? AND id = ?"),
        insert_mask(db,
                    "INSERT OR REPLACE INTO masks(session_id, keyframe, width, height, encoding, "
                    "bytes) VALUES(?, ?, ?, ?, ?, ?)") {}

  SqliteStatement map_id, insert_map, touch_map, insert_session, end_session;
  SqliteStatement clear_keyframes, clear_points, clear_masks;
  SqliteStatement insert_keyframe, update_pose, erase_keyframe, erase_mask;
  SqliteStatement insert_point, move_point, erase_point, insert_mask;
};

// Schema version 2 on: what a writer keeps of keyframes' places (a reader may open a version 1
// store, which has no such table).
struct SqliteMapStore::PlaceStatements {
  explicit PlaceStatements(SqliteDatabase& db)
      : clear(db, "DELETE FROM keyframe_places WHERE session_id = ?"),
        erase(db, "DELETE FROM keyframe_places WHERE session_id = ? AND keyframe = ?"),
        // Only beside a stored keyframe: a place whose keyframe was erased meanwhile is dropped.
        insert(db,
               "INSERT OR REPLACE INTO keyframe_places(session_id, keyframe, vocabulary, "
               "direct_index_depth, bow, direct_index) SELECT ?1, ?2, ?3, ?4, ?5, ?6 WHERE "
               "EXISTS(SELECT 1 FROM keyframes WHERE session_id = ?1 AND id = ?2)") {}

  SqliteStatement clear, erase, insert;
};

SqliteMapStore::SqliteMapStore(const std::filesystem::path& file, MapStoreAccess access,
                               int lock_fd)
    : file_(file),
      lock_fd_(lock_fd),
      db_(file, access == MapStoreAccess::kRead, access == MapStoreAccess::kServe) {
  const bool writable = access != MapStoreAccess::kRead;
  if (writable && sqlite3_db_readonly(db_.handle(), "main") == 1) {
    throw StoreError(file.string() + ": the map store is read-only");
  }
  try {
    db_.execute("PRAGMA foreign_keys = ON");
    // Pages read in place rather than copied in by a read() each: a 1000-keyframe map's ~30 000
    // pages of features were a fifth of reading it. (Address space only; SQLite maps what the file
    // holds and reads the rest as before.)
    db_.execute("PRAGMA mmap_size = 1073741824");
    {
      SqliteStatement check(db_, "PRAGMA quick_check(1)");
      if (check.step() && check.columnText(0) != "ok") {
        std::string finding = check.columnText(0);
        std::replace(finding.begin(), finding.end(), '\n', ' ');
        throw StoreError("the map store is damaged (malformed: " + finding + ")");
      }
    }
    // Before anything is written (WAL mode changes the header): a store that will be refused is
    // left byte for byte as it was.
    checkSchema(db_, writable);
    if (writable) {
      {
        SqliteStatement journal(db_, "PRAGMA journal_mode = WAL");
        if (!journal.step() || journal.columnText(0) != "wal") {
          throw StoreError("cannot switch the map store to WAL mode");
        }
      }
      // WAL with NORMAL: a killed process loses nothing committed; a power cut at most the last
      // transactions, never the store.
      db_.execute("PRAGMA synchronous = NORMAL");
      prepareSchema(db_);
    }
    statements_ = std::make_unique<Statements>(db_);
    if (schemaVersion(db_) >= 2) place_statements_ = std::make_unique<PlaceStatements>(db_);
  } catch (const std::exception& e) {
    throw StoreError(withFile(db_, e));
  }
}

SqliteMapStore::~SqliteMapStore() {
  statements_.reset();
  place_statements_.reset();
  if (lock_fd_ >= 0) close(lock_fd_);
}

std::optional<std::int64_t> SqliteMapStore::mapId(const std::string& name) {
  SqliteStatement& s = statements_->map_id;
  s.bind(1, name);
  std::optional<std::int64_t> id;
  if (s.step()) id = s.columnInt(0);
  s.reset();
  return id;
}

MapSummary SqliteMapStore::summary(std::int64_t map_id, const std::string& name) {
  MapSummary out;
  out.name = name;
  {
    SqliteStatement s(db_, "SELECT created, updated FROM maps WHERE id = ?");
    s.bind(1, map_id);
    if (s.step()) {
      out.created = s.columnDouble(0);
      out.updated = s.columnDouble(1);
    }
  }
  {
    SqliteStatement s(db_, "SELECT count(*) FROM sessions WHERE map_id = ?");
    s.bind(1, map_id);
    if (s.step()) out.sessions = static_cast<std::uint64_t>(s.columnInt(0));
  }
  {
    SqliteStatement s(db_, "SELECT count(*) FROM sessions WHERE map_id = ? AND sensor != ?");
    s.bind(1, map_id);
    s.bind(2, std::string(toString(Sensor::kMonocular)));
    if (s.step()) out.metric = s.columnInt(0) > 0;
  }
  {
    SqliteStatement s(db_,
                      "SELECT count(*), coalesce(sum(length(pose) + length(keypoints) + "
                      "length(descriptors) + length(depth) + length(right_u) + 48), 0) FROM "
                      "keyframes WHERE session_id IN (SELECT id FROM sessions WHERE map_id = ?)");
    s.bind(1, map_id);
    if (s.step()) {
      out.keyframes = static_cast<std::uint64_t>(s.columnInt(0));
      out.bytes += static_cast<std::uint64_t>(s.columnInt(1));
    }
  }
  {
    SqliteStatement s(db_,
                      "SELECT count(*), coalesce(sum(length(descriptor) + length(observations) + "
                      "80), 0), min(x), min(y), min(z), max(x), max(y), max(z) FROM points WHERE "
                      "session_id IN (SELECT id FROM sessions WHERE map_id = ?)");
    s.bind(1, map_id);
    if (s.step()) {
      out.points = static_cast<std::uint64_t>(s.columnInt(0));
      out.bytes += static_cast<std::uint64_t>(s.columnInt(1));
      if (out.points > 0) {
        out.extent_min = {s.columnDouble(2), s.columnDouble(3), s.columnDouble(4)};
        out.extent_max = {s.columnDouble(5), s.columnDouble(6), s.columnDouble(7)};
      }
    }
  }
  {
    SqliteStatement s(db_,
                      "SELECT coalesce(sum(length(bytes) + 24), 0) FROM masks WHERE session_id "
                      "IN (SELECT id FROM sessions WHERE map_id = ?)");
    s.bind(1, map_id);
    if (s.step()) out.bytes += static_cast<std::uint64_t>(s.columnInt(0));
  }
  if (place_statements_) {
    SqliteStatement s(db_,
                      "SELECT coalesce(sum(length(bow) + length(direct_index) + 24), 0) FROM "
                      "keyframe_places WHERE session_id IN (SELECT id FROM sessions WHERE "
                      "map_id = ?)");
    s.bind(1, map_id);
    if (s.step()) out.bytes += static_cast<std::uint64_t>(s.columnInt(0));
  }
  return out;
}

std::vector<MapSummary> SqliteMapStore::listMaps() {
  MutexLock lock(mutex_);
  std::vector<std::pair<std::int64_t, std::string>> maps;
  {
    SqliteStatement s(db_, "SELECT id, name FROM maps ORDER BY name");
    while (s.step()) maps.emplace_back(s.columnInt(0), s.columnText(1));
  }
  std::vector<MapSummary> out;
  for (const auto& [id, name] : maps) out.push_back(summary(id, name));
  return out;
}

std::optional<MapSummary> SqliteMapStore::mapInfo(const std::string& name) {
  MutexLock lock(mutex_);
  const auto id = mapId(name);
  if (!id) return std::nullopt;
  return summary(*id, name);
}

StoredSession SqliteMapStore::loadSession(SqliteStatement& row) {
  StoredSession session;
  session.id = row.columnInt(0);
  session.info.client = row.columnText(1);
  session.info.sensor = sensorFromName(row.columnText(2));
  CameraIntrinsics c;
  c.width = static_cast<int>(row.columnInt(3));
  c.height = static_cast<int>(row.columnInt(4));
  c.fx = row.columnDouble(5);
  c.fy = row.columnDouble(6);
  c.cx = row.columnDouble(7);
  c.cy = row.columnDouble(8);
  c.distortion = {row.columnDouble(9), row.columnDouble(10), row.columnDouble(11),
                  row.columnDouble(12), row.columnDouble(13)};
  c.baseline_m = row.columnDouble(14);
  c.depth_factor = row.columnDouble(15);
  c.fps = row.columnDouble(16);
  try {
    session.info.camera = PinholeCamera(c);
  } catch (const std::invalid_argument& e) {
    throw StoreError(std::string("damaged camera of a session: ") + e.what());
  }
  session.started = row.columnDouble(17);
  session.ended = row.columnDouble(18);

  Stopwatch timer;
  SqliteStatement keyframes(db_,
                            "SELECT id, frame_index, timestamp, pose, parent, pyramid_levels, "
                            "scale_factor, bf, keypoints, descriptors, depth, right_u FROM "
                            "keyframes WHERE session_id = ? ORDER BY id");
  keyframes.bind(1, session.id);
  {
    // Reserved: a record's cv::Mat moves without noexcept, so a growing vector would copy each
    // keyframe's features again (a quarter of reading a 1000-keyframe map).
    SqliteStatement count(db_, "SELECT count(*) FROM keyframes WHERE session_id = ?");
    count.bind(1, session.id);
    if (count.step()) session.keyframes.reserve(static_cast<std::size_t>(count.columnInt(0)));
  }
  std::unordered_map<KeyFrameId, std::size_t> keyframe_index;
  keyframe_index.reserve(session.keyframes.capacity());
  while (keyframes.step()) {
    KeyFrameRecord k;
    k.id = fromSql(keyframes.columnInt(0));
    k.frame_index = static_cast<std::uint64_t>(keyframes.columnInt(1));
    k.timestamp = keyframes.columnDouble(2);
    k.T_cw = poseFromBlob(keyframes.columnBlobView(3));
    k.parent = fromSql(keyframes.columnInt(4));
    k.features.pyramid_levels = static_cast<int>(keyframes.columnInt(5));
    k.features.scale_factor = keyframes.columnDouble(6);
    k.features.bf = static_cast<float>(keyframes.columnDouble(7));
    k.features.keypoints = keypointsFromBlob(keyframes.columnBlobView(8));
    k.features.descriptors = descriptorsFromBlob(keyframes.columnBlobView(9));
    k.features.depth = floatsFromBlob(keyframes.columnBlobView(10));
    k.features.right_u = floatsFromBlob(keyframes.columnBlobView(11));
    const std::size_t n = k.features.keypoints.size();
    if (static_cast<std::size_t>(k.features.descriptors.rows) != n ||
        (!k.features.depth.empty() && k.features.depth.size() != n) ||
        (!k.features.right_u.empty() && k.features.right_u.size() != n)) {
      throw StoreError("damaged keyframe " + std::to_string(k.id) +
                       ": keypoints, descriptors and depths disagree");
    }
    k.point_ids.assign(n, kInvalidId);
    keyframe_index[k.id] = session.keyframes.size();
    session.keyframes.push_back(std::move(k));
  }

  const double keyframes_ms = timer.elapsedMs();
  SqliteStatement points(db_,
                         "SELECT id, x, y, z, nx, ny, nz, descriptor, min_distance, "
                         "max_distance, reference, observations FROM points WHERE session_id = "
                         "? ORDER BY id");
  points.bind(1, session.id);
  while (points.step()) {
    MapPointRecord p;
    p.id = fromSql(points.columnInt(0));
    p.position = {points.columnDouble(1), points.columnDouble(2), points.columnDouble(3)};
    p.normal = {points.columnDouble(4), points.columnDouble(5), points.columnDouble(6)};
    const BlobView descriptor = points.columnBlobView(7);
    if (descriptor.size() != p.descriptor.size()) {
      throw StoreError("damaged descriptor of point " + std::to_string(p.id));
    }
    std::memcpy(p.descriptor.data(), descriptor.data(), descriptor.size());
    p.min_distance = static_cast<float>(points.columnDouble(8));
    p.max_distance = static_cast<float>(points.columnDouble(9));
    p.reference_keyframe = fromSql(points.columnInt(10));
    p.observations = observationsFromBlob(points.columnBlobView(11));
    for (const PointObservationRecord& o : p.observations) {
      const auto it = keyframe_index.find(o.keyframe);
      if (it == keyframe_index.end()) continue;
      KeyFrameRecord& k = session.keyframes[it->second];
      if (o.keypoint_index < k.point_ids.size()) k.point_ids[o.keypoint_index] = p.id;
    }
    session.points.push_back(std::move(p));
  }

  const double points_ms = timer.elapsedMs();
  if (place_statements_) loadPlaces(session, keyframe_index);
  const double places_ms = timer.elapsedMs();

  SqliteStatement masks(db_,
                        "SELECT keyframe, width, height, encoding, bytes FROM masks WHERE "
                        "session_id = ? ORDER BY keyframe");
  masks.bind(1, session.id);
  while (masks.step()) {
    MaskRecord m;
    m.keyframe = fromSql(masks.columnInt(0));
    m.width = static_cast<int>(masks.columnInt(1));
    m.height = static_cast<int>(masks.columnInt(2));
    m.encoding = masks.columnText(3);
    m.bytes = masks.columnBlob(4);
    session.masks.push_back(std::move(m));
  }
  spdlog::debug(
      "stored session read: keyframes {:.0f} ms, points {:.0f} ms, places {:.0f} ms, masks {:.0f} "
      "ms",
      keyframes_ms, points_ms - keyframes_ms, places_ms - points_ms, timer.elapsedMs() - places_ms);
  return session;
}

void SqliteMapStore::loadPlaces(StoredSession& session,
                                const std::unordered_map<KeyFrameId, std::size_t>& keyframe_index) {
  SqliteStatement places(db_,
                         "SELECT keyframe, vocabulary, direct_index_depth, bow, direct_index FROM "
                         "keyframe_places WHERE session_id = ? ORDER BY keyframe");
  places.bind(1, session.id);
  while (places.step()) {
    KeyFramePlaceRecord p;
    p.keyframe = fromSql(places.columnInt(0));
    const auto it = keyframe_index.find(p.keyframe);
    if (it == keyframe_index.end()) continue;  // its keyframe is gone
    p.vocabulary = fromSql(places.columnInt(1));
    p.direct_index_depth = static_cast<int>(places.columnInt(2));
    p.bow = bowFromBlob(places.columnBlobView(3));
    p.features = featureVectorFromBlob(places.columnBlobView(4));
    const std::size_t keypoints = session.keyframes[it->second].features.keypoints.size();
    for (std::size_t i = 0; i < p.features.size(); ++i) {
      for (const int index : p.features.features(i)) {
        if (static_cast<std::size_t>(index) >= keypoints) {
          throw StoreError("damaged direct index of keyframe " + std::to_string(p.keyframe) +
                           ": feature " + std::to_string(index) + " of " +
                           std::to_string(keypoints));
        }
      }
    }
    session.places.push_back(std::move(p));
  }
}

std::optional<StoredMap> SqliteMapStore::loadMap(const std::string& name) {
  MutexLock lock(mutex_);
  try {
    const auto id = mapId(name);
    if (!id) return std::nullopt;
    StoredMap map;
    map.name = name;
    SqliteStatement sessions(db_,
                             "SELECT id, client, sensor, width, height, fx, fy, cx, cy, k1, k2, "
                             "p1, p2, k3, baseline_m, depth_factor, fps, started, ended FROM "
                             "sessions WHERE map_id = ? ORDER BY id");
    sessions.bind(1, *id);
    while (sessions.step()) map.sessions.push_back(loadSession(sessions));
    return map;
  } catch (const std::exception& e) {
    throw StoreError(withFile(db_, e));
  }
}

StoreSessionId SqliteMapStore::beginSession(const std::string& map, const StoredSessionInfo& info) {
  MutexLock lock(mutex_);
  SqliteTransaction transaction(db_);
  const double now = nowSeconds();
  std::int64_t map_id = 0;
  if (const auto existing = mapId(map)) {
    map_id = *existing;
  } else {
    SqliteStatement& s = statements_->insert_map;
    s.bind(1, map).bind(2, now).bind(3, now).run();
    map_id = sqlite3_last_insert_rowid(db_.handle());
  }
  const CameraIntrinsics& c = info.camera.intrinsics();
  SqliteStatement& s = statements_->insert_session;
  s.bind(1, map_id).bind(2, info.client).bind(3, std::string(toString(info.sensor)));
  s.bind(4, std::int64_t{c.width}).bind(5, std::int64_t{c.height});
  s.bind(6, c.fx).bind(7, c.fy).bind(8, c.cx).bind(9, c.cy);
  s.bind(10, c.distortion.k1).bind(11, c.distortion.k2).bind(12, c.distortion.p1);
  s.bind(13, c.distortion.p2).bind(14, c.distortion.k3);
  s.bind(15, c.baseline_m).bind(16, c.depth_factor).bind(17, c.fps).bind(18, now);
  s.run();
  const StoreSessionId session = sqlite3_last_insert_rowid(db_.handle());
  transaction.commit();
  return session;
}

void SqliteMapStore::write(StoreSessionId session, const MapStoreBatch& batch) {
  if (batch.empty()) return;
  MutexLock lock(mutex_);
  Statements& s = *statements_;
  SqliteTransaction transaction(db_);
  if (batch.cleared) {
    s.clear_keyframes.bind(1, session).run();
    s.clear_points.bind(1, session).run();
    s.clear_masks.bind(1, session).run();
    if (place_statements_) place_statements_->clear.bind(1, session).run();
  }
  for (const KeyFrameRecord& k : batch.keyframes) {
    SqliteStatement& q = s.insert_keyframe;
    q.bind(1, session).bind(2, toSql(k.id)).bind(3, static_cast<std::int64_t>(k.frame_index));
    q.bind(4, k.timestamp).bindBlob(5, poseBlob(k.T_cw)).bind(6, toSql(k.parent));
    q.bind(7, std::int64_t{k.features.pyramid_levels}).bind(8, k.features.scale_factor);
    q.bind(9, static_cast<double>(k.features.bf));
    q.bindBlob(10, keypointsBlob(k.features.keypoints));
    q.bindBlob(11, descriptorsBlob(k.features.descriptors));
    q.bindBlob(12, floatsBlob(k.features.depth)).bindBlob(13, floatsBlob(k.features.right_u));
    q.run();
  }
  for (const KeyFramePoseRecord& p : batch.poses) {
    s.update_pose.bindBlob(1, poseBlob(p.T_cw)).bind(2, toSql(p.parent)).bind(3, session);
    s.update_pose.bind(4, toSql(p.id)).run();
  }
  for (const MapPointRecord& p : batch.points) {
    SqliteStatement& q = s.insert_point;
    q.bind(1, session).bind(2, toSql(p.id));
    q.bind(3, p.position.x()).bind(4, p.position.y()).bind(5, p.position.z());
    q.bind(6, p.normal.x()).bind(7, p.normal.y()).bind(8, p.normal.z());
    q.bindBlob(9, p.descriptor).bind(10, static_cast<double>(p.min_distance));
    q.bind(11, static_cast<double>(p.max_distance)).bind(12, toSql(p.reference_keyframe));
    q.bindBlob(13, observationsBlob(p.observations));
    q.run();
  }
  for (const MapPointRecord& p : batch.points_moved) {
    SqliteStatement& q = s.move_point;
    q.bind(1, p.position.x()).bind(2, p.position.y()).bind(3, p.position.z());
    q.bind(4, p.normal.x()).bind(5, p.normal.y()).bind(6, p.normal.z());
    q.bind(7, static_cast<double>(p.min_distance)).bind(8, static_cast<double>(p.max_distance));
    q.bind(9, session).bind(10, toSql(p.id)).run();
  }
  for (const MapPointId id : batch.points_erased) {
    s.erase_point.bind(1, session).bind(2, toSql(id)).run();
  }
  for (const KeyFrameId id : batch.keyframes_erased) {
    s.erase_keyframe.bind(1, session).bind(2, toSql(id)).run();
    s.erase_mask.bind(1, session).bind(2, toSql(id)).run();
    if (place_statements_) place_statements_->erase.bind(1, session).bind(2, toSql(id)).run();
  }
  for (const MaskRecord& m : batch.masks) {
    SqliteStatement& q = s.insert_mask;
    q.bind(1, session).bind(2, toSql(m.keyframe)).bind(3, std::int64_t{m.width});
    q.bind(4, std::int64_t{m.height}).bind(5, m.encoding).bindBlob(6, m.bytes).run();
  }
  if (place_statements_) {
    for (const KeyFramePlaceRecord& p : batch.places) {
      SqliteStatement& q = place_statements_->insert;
      q.bind(1, session).bind(2, toSql(p.keyframe)).bind(3, toSql(p.vocabulary));
      q.bind(4, std::int64_t{p.direct_index_depth}).bindBlob(5, bowBlob(p.bow));
      q.bindBlob(6, featureVectorBlob(p.features)).run();
    }
  }
  s.touch_map.bind(1, nowSeconds()).bind(2, session).run();
  transaction.commit();
}

void SqliteMapStore::endSession(StoreSessionId session) {
  MutexLock lock(mutex_);
  statements_->end_session.bind(1, nowSeconds()).bind(2, session).run();
}

void SqliteMapStore::resumeSession(StoreSessionId session) {
  MutexLock lock(mutex_);
  statements_->end_session.bind(1, 0.0).bind(2, session).run();
}

bool SqliteMapStore::removeMap(const std::string& name) {
  MutexLock lock(mutex_);
  const auto id = mapId(name);
  if (!id) return false;
  SqliteTransaction transaction(db_);
  SqliteStatement s(db_, "DELETE FROM maps WHERE id = ?");
  s.bind(1, *id).run();
  transaction.commit();
  return true;
}

std::unique_ptr<MapStore> openMapStore(const std::filesystem::path& directory,
                                       MapStoreAccess access) {
  const std::filesystem::path file = directory / "maps.sqlite";
  if (access == MapStoreAccess::kServe) {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error) {
      throw StoreError(file.string() + ": cannot create the store's folder: " + error.message());
    }
  } else if (!std::filesystem::exists(file)) {
    throw StoreError(file.string() + ": no map store there");
  }
  int lock_fd = -1;
  if (access != MapStoreAccess::kRead) {
    const std::filesystem::path lock_file = directory / "maps.lock";
    lock_fd = open(lock_file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lock_fd < 0) {
      throw StoreError(file.string() + ": cannot write the store's lock file " +
                       lock_file.string() + ": " + std::strerror(errno));
    }
    if (flock(lock_fd, LOCK_EX | LOCK_NB) != 0) {
      close(lock_fd);
      throw StoreError(file.string() +
                       ": the map store is locked by another edgeslam process writing to it");
    }
  }
  try {
    return std::make_unique<SqliteMapStore>(file, access, lock_fd);
  } catch (...) {
    if (lock_fd >= 0) close(lock_fd);
    throw;
  }
}

}  // namespace edgeslam
