#pragma once
// The client's keyframe sink in edge mode: turns each new keyframe (and the points the client made
// with it) into an upload, learns from the slices which keyframes the edge has mapped, and forgets
// the keyframes whose upload the link dropped.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <set>
#include <unordered_set>
#include <vector>

#include "client/keyframe_uplink.h"
#include "geometry/camera.h"
#include "map/keyframe_sink.h"
#include "map/map.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

struct EdgeKeyFrameSinkOptions {
  // Tracking holds back optional keyframes while this many uploads wait for their slice.
  std::size_t max_in_flight = 3;
  // Starving tracking may have this many more in flight (below the link's queue of 8, so none
  // is dropped for it): behind a congested link the edge answers seconds late, and a monocular
  // client refused its keyframes lost tracking for good at the first fast turn.
  std::size_t urgent_extra_in_flight = 3;
  // While the edge is unreachable (uplink reconnecting) tracking goes on making keyframes at its
  // own pace, up to this many unanswered: they wait in the uplink's queue (which must hold more)
  // and reach the edge when it is back. Refusing them starved tracking through a server restart.
  std::size_t max_in_flight_reconnecting = 24;
  // With the camera, new points that are the depth back-projection of their keypoint in the
  // uploaded keyframe are flagged so that the wire leaves their positions out (~12 bytes each).
  std::optional<PinholeCamera> camera;
};

class EdgeKeyFrameSink : public KeyFrameSink {
 public:
  EdgeKeyFrameSink(Map& map, KeyFrameUplink& uplink, EdgeKeyFrameSinkOptions options = {});

  void insertKeyFrame(KeyFrame* keyframe) override;
  // Uploads again a keyframe the edge lost (a full resync did not list it), with every point of
  // this client it sees (the edge skips those it has). Call on the tracking thread, as
  // insertKeyFrame, so that uploads leave in sequence order. False when the keyframe is gone.
  bool resendKeyFrame(KeyFrameId keyframe);
  std::uint64_t keyFramesResent() const { return keyframes_resent_.load(); }
  bool acceptsKeyFrames() const override;
  bool acceptsUrgentKeyFrames() const override;
  std::size_t lastOptimizedFrame() const override { return last_optimized_frame_.load(); }
  bool mapUpdatesPaused() const override { return uplink_.reconnecting(); }
  void onMapReset() override;

  // The image of the frame about to be tracked: if that frame becomes a keyframe, the image goes
  // up with it (for segmentation on the edge). Call on the tracking thread.
  void attachImage(std::size_t frame_index, cv::Mat image);
  // The segmenter NMS threshold the next uploads ask the edge for (0 = the edge's own).
  void setSegmenterNms(float nm) { segmenter_nms_ = nm; }

  // A slice answering upload `upload_sequence` was applied; returns the seconds since that upload
  // was sent (negative when unknown), for the slice-latency statistics.
  double onSliceApplied(std::uint64_t upload_sequence, std::size_t processed_frame_index);

  // The link gave up on upload `upload_sequence`, which carried `keyframe`: the edge will never
  // map them, so no slice would ever evict, correct or cull the keyframe nor the points that went
  // up with it. Under the map's update mutex the client forgets them: those points are erased,
  // points the edge knows only lose this keyframe's observation, and the keyframe is erased (the
  // map's origin, which cannot be erased, keeps only its pose). The upload no longer counts as in
  // flight. Returns whether a keyframe was forgotten (false when the map no longer has it).
  // Any thread; not under the map's update mutex.
  bool onUploadDropped(std::uint64_t upload_sequence, KeyFrameId keyframe);

  std::uint64_t uploadsSent() const { return sequence_.load(); }
  std::uint64_t uploadsAnswered() const { return answered_.load(); }
  // Uploads that may still be answered by a slice (sent, not answered, not dropped).
  std::uint64_t uploadsInFlight() const;
  // Of those, the ones sent after the last outage's backlog (the uploads sent while the edge was
  // unreachable, and those sent again after its restart): the bounds above apply to these once
  // the edge is back, and max_in_flight_reconnecting to all. The edge answers the backlog in
  // order, a second or more per keyframe on a loaded host; counted against max_in_flight it
  // refused tracking every keyframe until then, and tracking was lost (14 keyframes of a server
  // restart in flight, no keyframe for 2 s, lost at the next turn for 200 frames).
  std::uint64_t uploadsInFlightAfterBacklog() const;
  bool allAnswered() const { return uploadsInFlight() == 0; }
  std::uint64_t keyFramesForgotten() const { return keyframes_forgotten_.load(); }
  std::uint64_t pointsForgotten() const { return points_forgotten_.load(); }

 private:
  using Clock = std::chrono::steady_clock;
  // What an upload carried that the edge learns from it alone.
  struct UploadRecord {
    std::uint64_t sequence = 0;
    KeyFrameId keyframe = kInvalidId;
    std::vector<MapPointId> new_points;
    bool map_reset = false;
  };
  // Uploads remembered for onUploadDropped: well beyond the link's queue and those in flight.
  static constexpr std::size_t kRememberedUploads = 64;

  void sendUpload(KeyFrame* keyframe, bool resend);
  // Uploads in flight with a sequence above `floor`.
  std::uint64_t inFlightAbove(std::uint64_t floor) const;
  // Whether `limit` uploads after the backlog (all of them while reconnecting: the reconnecting
  // bound) leave room for one more.
  bool withinBounds(std::size_t limit) const;

  Map& map_;
  KeyFrameUplink& uplink_;
  EdgeKeyFrameSinkOptions options_;
  std::atomic<std::uint64_t> sequence_{0};
  std::atomic<std::uint64_t> answered_{0};
  std::atomic<std::size_t> last_optimized_frame_{0};
  bool reset_pending_ = false;
  std::atomic<float> segmenter_nms_{0.f};
  std::size_t image_frame_ = 0;
  cv::Mat image_;
  static constexpr std::size_t kForgetUploadedPointsEvery = 4096;
  std::unordered_set<MapPointId> uploaded_points_;
  std::deque<UploadRecord> recent_uploads_;  // guarded by the map's update mutex
  mutable Mutex sent_mutex_;
  std::deque<std::pair<std::uint64_t, Clock::time_point>> sent_times_ GUARDED_BY(sent_mutex_);
  std::set<std::uint64_t> dropped_unanswered_
      GUARDED_BY(sent_mutex_);                           // dropped sequences above answered_
  std::atomic<std::uint64_t> backlog_last_sequence_{0};  // last upload of the outage's backlog
  std::atomic<std::uint64_t> keyframes_forgotten_{0};
  std::atomic<std::uint64_t> keyframes_resent_{0};
  std::atomic<std::uint64_t> points_forgotten_{0};
};

}  // namespace edgeslam
