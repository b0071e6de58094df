#pragma once
// What an edge server session does: in edge mode it keeps the client's global map (keyframe
// uploads in, map slices out); in offload mode it runs the whole SLAM on the frames it is sent.
#include <atomic>
#include <memory>
#include <optional>

#include "modes/live_edge_maps.h"
#include "modes/local_slam.h"
#include "modes/slam_system.h"
#include "server/edge_localization_session.h"
#include "server/edge_map_session.h"
#include "store/map_store_writer.h"
#include "util/mutex.h"
#include "wire/edge_server.h"

namespace edgeslam {

struct SlamSessionOptions {
  EdgeMapSessionOptions mapping;
  // Sessions that ask for semantic culling get a segmenter made with these; without, such a
  // session is refused.
  std::optional<SegmenterOptions> segmenter;
  // Edge sessions write their map here as it changes (nullptr = kept in memory only), into the
  // map the client names or a new one; what the writers did is added to store_stats.
  std::shared_ptr<MapStore> store;
  std::shared_ptr<MapStoreWriteStats> store_stats;
};

class SlamSessionBackend : public EdgeSessionBackend {
 public:
  // `live_maps`: the maps the server's other sessions write now; a session naming one of them
  // joins it (nullptr: each session has a map of its own).
  SlamSessionBackend(const SessionConfig& config, SliceSink& sink, SlamSessionOptions options,
                     std::shared_ptr<LiveEdgeMaps> live_maps = nullptr);
  ~SlamSessionBackend() override;

  void onKeyFrame(KeyFrameUpload upload) override;
  std::optional<OffloadResult> onFrame(OffloadFrame frame) override;
  // Edge mode: a slice with full_resync (every keyframe's pose and every point), split when
  // larger than a message.
  void onFullResyncRequested() override;
  std::uint64_t idFloor() const override { return id_floor_; }
  std::optional<std::string> failure() const override;
  // Edge mode: per keyframe mapped, local BA, loop detection; per loop correction and global BA.
  // Localise-only: per relocalisation of a lost frame against the whole map.
  BackendCosts costs() const override;

  // For a viewer, from any thread: the session's map now (its global map in edge mode, the
  // offloaded SLAM's map in offload mode; empty before the first keyframe or frame) and the loops
  // it closed.
  MapSample mapSample(std::size_t max_points) const;
  std::size_t loops() const;
  // The loops closed in the session's map (a shared map's: every client's), merges included.
  std::vector<LoopEvent> loopEvents() const;
  // The map the session writes or localises in, for a viewer: its name in the store ("" when the
  // server keeps none and the client named none) and an identity the sessions of one shared map
  // have in common (nullptr before the session has a map).
  struct MapIdentity {
    std::string name;
    const void* map = nullptr;
    bool localize_only = false;
  };
  MapIdentity mapIdentity() const;
  // The top byte of the ids of the keyframes this session's client makes.
  std::uint8_t clientIdOrigin() const { return config_.id_origin; }

 private:
  // The map's latest stored session with keyframes, when the session names a stored map.
  std::optional<StoredSession> storedSessionToResume();
  std::shared_ptr<LiveEdgeMap> makeMapping(std::optional<StoredSession> resumed);
  // Writes into the map another session of the server is writing. Throws std::invalid_argument
  // when this client cannot (whyCannotJoin).
  void joinMapping(std::shared_ptr<LiveEdgeMap> live);
  EdgeMapSession& mapping() const { return *mapping_->session; }
  // A localise-only session: the stored map it names, read-only. Throws std::invalid_argument when
  // the edge cannot serve it (no store, no such map, another sensor, no vocabulary).
  void makeLocalization();
  void startStoreWriter(LiveEdgeMap& live, std::optional<StoreSessionId> resumed,
                        const std::vector<KeyFrameId>& stored_keyframes,
                        const std::vector<KeyFrameId>& places_missing);
  void publish(MapSlice slice);

  // Held where mapping_ and offload_ are made and where a viewer's thread reads them. Not
  // GUARDED_BY: the session's own thread, their only writer, reads them without it.
  mutable Mutex view_mutex_;
  SessionConfig config_;
  // The map's name in the store: the client's --map, else one made for this session.
  std::string store_map_name_;
  SliceSink& sink_;
  SlamSessionOptions options_;
  std::shared_ptr<Segmenter> segmenter_;  // when the session asked for semantic culling
  std::shared_ptr<LiveEdgeMaps> live_maps_;
  // Edge mode: the map, made when the session opens (a named map) or at the first keyframe; shared
  // with the other sessions writing the same named map.
  std::shared_ptr<LiveEdgeMap> mapping_;
  EdgeMapClientId client_ = 0;                             // this session's client in mapping_
  std::unique_ptr<EdgeLocalizationSession> localization_;  // localise-only edge sessions
  std::unique_ptr<LocalSlam> offload_;                     // offload mode, made at the first frame
  std::uint64_t id_floor_ = 0;
  // A client that joined a map another session writes: its own session in the store, for the
  // record (who, when; its keyframes are written with the map's writer).
  std::optional<StoreSessionId> joined_store_session_;
  std::atomic<std::uint64_t> slices_split_{0};     // slices sent as several parts
  std::atomic<std::uint64_t> slices_not_sent_{0};  // slices that could not be sent (logged)
};

class SlamSessionFactory : public EdgeSessionFactory {
 public:
  explicit SlamSessionFactory(SlamSessionOptions options = {})
      : options_(options), live_maps_(std::make_shared<LiveEdgeMaps>()) {}
  std::unique_ptr<EdgeSessionBackend> open(const SessionConfig& config, SliceSink& sink) override;

 private:
  SlamSessionOptions options_;
  std::shared_ptr<LiveEdgeMaps> live_maps_;
};

}  // namespace edgeslam
