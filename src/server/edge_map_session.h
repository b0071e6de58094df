#pragma once
// A map on the edge and the clients that map into it: the global map, fed by the clients' keyframe
// uploads and kept by local mapping on its own thread and, with a vocabulary, by loop closing on
// another; after each mapped keyframe, loop correction and global bundle adjustment, what changed
// goes back to each client as a map slice bounded to its own window. One client (made with the
// session) is the common case; others join a named map another client writes (addClient), each
// with its own window, slice sequence and uploads.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "geometry/camera.h"
#include "geometry/sim3.h"
#include "map/map.h"
#include "map/map_change_observer.h"
#include "map/map_records.h"
#include "map/sensor.h"
#include "mapping/mapping_backend.h"
#include "server/client_map_window.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

// An edge session's back end by default: as local mode's, but with a segmenter, mapping and loop
// closing run at least nice 10. On the edge's one core a late mask costs the client more than a
// late map point: 7-Scenes seed 11, 5 edge runs each, segmentation 137-156 ms instead of 201-252
// and the transferred-mask IoU 0.42-0.61 instead of 0.00-0.48, ATE no worse.
MappingBackendOptions edgeSessionBackendOptions();

struct EdgeMapSessionOptions {
  // Mapping, loop closing and, with backend.segmenter, segmentation of keyframes uploaded with an
  // image (one segmenter per session). backend.threaded = false maps each keyframe inside
  // onKeyFrame (deterministic tests).
  MappingBackendOptions backend = edgeSessionBackendOptions();
  int mask_downscale = 4;  // the label image travels at 1/this of the camera's resolution
  // The client's bounded map (window.keyframes = 0: it replicates the whole global map).
  ClientMapWindowOptions window;
  // Fills the empty global map before the session's threads start (a stored map resumed after a
  // server restart); its keyframes are then described (bags of words), filed for place
  // recognition and taken as held by the client.
  std::function<void(Map&)> preload;
};

// A client of the session: 0 is the one it was made with.
using EdgeMapClientId = std::uint32_t;

struct EdgeMapSessionStats {
  std::uint64_t uploads = 0;
  std::uint64_t slices = 0;
  std::uint64_t keyframes = 0;
  std::uint64_t map_points = 0;
  std::uint64_t keyframes_segmented = 0;
  std::uint64_t movable_points_erased = 0;
  std::uint64_t client_keyframes_held = 0;  // bounded client map: as the edge counts them
  std::uint64_t client_keyframes_evicted = 0;
  std::uint64_t client_keyframes_resent = 0;  // sent back into the window
  // Uploaded keypoints whose descriptor the wire left out: filled from their map point, or lost
  // (the point was gone: the keypoint keeps neither point nor descriptor).
  std::uint64_t descriptors_filled = 0;
  std::uint64_t descriptors_lost = 0;
  // Uploads of a keyframe the map already had (a client re-sending after a full resync): answered
  // by a slice, not mapped again.
  std::uint64_t uploads_duplicate = 0;
  std::uint64_t full_resyncs = 0;      // slices with full_resync published
  std::uint64_t keyframes_loaded = 0;  // by options.preload
  double load_describe_ms = 0.0;       // bags of words of those
};

class EdgeMapSession {
 public:
  using Publish = std::function<void(MapSlice)>;

  EdgeMapSession(const PinholeCamera& camera, Sensor sensor, EdgeMapSessionOptions options,
                 Publish publish);
  ~EdgeMapSession();
  EdgeMapSession(const EdgeMapSession&) = delete;
  EdgeMapSession& operator=(const EdgeMapSession&) = delete;

  // Another client mapping into this map: it holds nothing yet, gets slices bounded to its own
  // window (window.keyframes > 0: it learns of the others' keyframes as they enter its window)
  // through `publish`, from its own sequence. Throws std::invalid_argument for an unbounded
  // window.
  EdgeMapClientId addClient(ClientMapWindowOptions window, Publish publish);
  // The client leaves: no slice goes to it once this returns. The map stays as it is.
  void removeClient(EdgeMapClientId client);
  std::size_t clientCount() const;
  // The largest id of this origin among the map's keyframes and points (0: none): a client
  // joining with that origin makes its ids above it.
  std::uint64_t largestIdOfOrigin(std::uint8_t origin) const;

  // Adds the keyframe and its new points to the global map and queues it for mapping. Descriptors
  // the upload left out (features.descriptor_omitted) are those of the points their keypoints
  // name (fillOmittedDescriptors). Throws std::invalid_argument for records that contradict
  // themselves or come from a client that is not in the session.
  void onKeyFrame(const KeyFrameUpload& upload, EdgeMapClientId client = 0);
  // Publishes to `client` a slice with full_resync set: the pose of every keyframe the edge map
  // holds (the list a client compares with its own to re-send what the edge lacks) and every
  // point. The changes pending are taken by it (and told to the observer) as an ordinary slice
  // takes them; the other clients get them in their next slice.
  void publishFullResync(EdgeMapClientId client = 0);
  // Waits until every queued keyframe is mapped and its slice published.
  void finish();
  void stop();

  EdgeMapSessionStats stats() const;
  // Why one of the session's workers (mapping, loop closing, segmentation) ended with an
  // exception: the session is over. nullopt while they run.
  std::optional<std::string> failure() const;
  Map& map() { return map_; }
  // The keyframes the first client holds (lock the map's update mutex while reading).
  const ClientMapWindow& clientWindow() const { return first_client_->window; }
  const LocalMapper& mapper() const { return backend_->mapper(); }
  // nullptr without a vocabulary or with loop closing off.
  const LoopCloser* loopCloser() const { return backend_->loopCloser(); }
  // nullptr without segmentation.
  const KeyFrameSegmentationWorker* segmentation() const { return backend_->segmentation(); }
  // Box NMS threshold of the segmenter (paper Table I's nm), from the next keyframe on.
  void setNmsThreshold(float nm);
  // Told every change of the global map (uploads applied too) and every mask; set before the
  // first keyframe. Not owned: it outlives the session's threads (stop() first).
  void setChangeObserver(MapChangeObserver* observer) { observer_ = observer; }

 private:
  // What the session keeps for each client (under the map's update mutex).
  struct Client {
    Client(ClientMapWindowOptions window_options, Publish publish_to)
        : publish(std::move(publish_to)), window(window_options) {}
    Publish publish;
    ClientMapWindow window;
    KeyFrameId window_centre = kInvalidId;  // its last mapped keyframe
    std::size_t loops_published = 0;
    // Loops that moved the part this client was mapping in (its last mapped keyframe's) onto
    // another part, and how many of them its slices told.
    std::size_t merges_moved = 0;
    std::size_t merges_published = 0;
    std::uint64_t slice_sequence = 0;
    std::unordered_map<KeyFrameId, std::uint64_t> upload_of_keyframe;
    KeyFrameId newest_keyframe = kInvalidId;
  };

  Client& clientLocked(EdgeMapClientId client) const REQUIRES(map_.updateMutex());
  // `mapped`: the keyframe just mapped, or nullptr for a loop correction or global BA.
  // `answers`: an upload of `answered` the slice answers although nothing was mapped for it (a
  // duplicate).
  void publishSlice(KeyFrame* mapped, std::uint64_t answers = 0, EdgeMapClientId answered = 0);
  // The slice of one client from the slice every client's is cut from; nullopt when nothing in
  // it concerns the client (only for clients the slice answers nothing).
  std::optional<MapSlice> sliceFor(Client& client, MapSlice slice, KeyFrame* mapped,
                                   bool answers_client, std::uint64_t answers, std::size_t loops,
                                   const std::vector<MaskRecord>& masks)
      REQUIRES(map_.updateMutex());
  void adoptPreloadedMap();
  void onSegmented(KeyFrameSegmentationResult result);
  void onPartsMerged(const MapPartMerge& merge) REQUIRES(map_.updateMutex());
  // Tells the client in `slice` of the loops closed since its last slice (`loops` in all so far).
  void tellLoops(Client& client, std::size_t loops, MapSlice& slice) REQUIRES(map_.updateMutex());
  // An upload tracked against a keyframe that a merge has moved since, before its client heard of
  // it, is in the frame the part had: the move it must make (new world point = move * old one),
  // nullopt when it needs none.
  std::optional<Sim3d> partMoveMissedBy(const KeyFrameRecord& record) REQUIRES(map_.updateMutex());

  // Parts of the map a loop moved onto another (two clients' parts merged).
  struct PartMove {
    Sim3d world;  // new world point = world * old one
    std::unordered_set<KeyFrameId> moved;
  };

  PinholeCamera camera_;
  Map map_;
  MapChangeObserver* observer_ = nullptr;
  int mask_downscale_;
  std::map<EdgeMapClientId, std::unique_ptr<Client>> clients_ GUARDED_BY(map_.updateMutex());
  EdgeMapClientId next_client_ GUARDED_BY(map_.updateMutex()) = 1;
  // Taken under the map's update mutex (the merge tells of a move while it holds it).
  Mutex moves_mutex_;
  std::vector<PartMove> part_moves_ GUARDED_BY(moves_mutex_);
  Client* first_client_ = nullptr;  // client 0, for clientWindow(); gone once it leaves

  // Mapping and loop closing publish from their own threads: slices leave in sequence order, and
  // a client leaves (removeClient) between two slices.
  Mutex publish_mutex_;
  mutable Mutex state_mutex_;  // guards the fields below (not the map)
  EdgeMapSessionStats stats_ GUARDED_BY(state_mutex_);
  std::vector<MaskRecord> pending_masks_ GUARDED_BY(state_mutex_);

  // Last: its threads stop (in stop()) before the state above goes.
  std::unique_ptr<MappingBackend> backend_;
};

}  // namespace edgeslam
