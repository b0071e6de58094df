#pragma once
// What a run mode counts, grouped by what it measures. Each group is zero where the mode has none
// of it (local mode exchanges nothing; offload tracks nothing on the client).
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "map/map_records.h"
#include "modes/paced_keyframe_sink.h"
#include "util/timing_stats.h"

namespace edgeslam {

// Keyframes up to the edge and slices back (edge and offload modes).
struct EdgeExchangeCounters {
  std::uint64_t uplink_bytes = 0;
  std::uint64_t downlink_bytes = 0;
  std::uint64_t keyframes_uploaded = 0;
  std::uint64_t uploads_dropped = 0;
  std::uint64_t uploads_overflowed = 0;  // of those, pushed out of the link's full queue
  // Sent, neither answered by a slice nor dropped when the run ended (a stalled link, a lost
  // edge): the edge may or may not have them.
  std::uint64_t uploads_unanswered = 0;
  std::uint64_t keyframes_forgotten = 0;  // by the client, their upload dropped
  std::uint64_t points_forgotten = 0;     // that went up with those uploads only
  std::uint64_t slices_applied = 0;
  std::uint64_t reconnects = 0;
  PercentileSummary slice_latency_ms;
  PercentileSummary slice_apply_ms;
  PercentileSummary edge_frame_ms;  // offload: the edge's time per frame
};

// Semantic culling: keyframes segmented where they are mapped, features culled on the client.
struct SemanticCounters {
  std::uint64_t keyframes_segmented = 0;
  std::uint64_t keyframes_not_segmented = 0;  // local mode: skipped by a full queue
  std::uint64_t movable_points_erased = 0;    // local mode (the edge erases its own)
  PercentileSummary segmentation_ms;          // per keyframe, where it ran
  PercentileSummary client_ms;                // mask transfer and culling per frame
  std::uint64_t frames_with_mask = 0;         // tracked with a mask transferred from a keyframe's
  std::uint64_t frames_without_mask = 0;      // tracked before any mask was back
  std::uint64_t features_culled = 0;
  // Frames by the age of their mask (frames since its keyframe): [age] up to 63, [64] beyond.
  std::array<std::uint64_t, 65> mask_age{};
};

// Where the client's time per frame goes (modes that track on the client).
struct ClientStageSummary {
  PercentileSummary features_ms;  // ORB extraction, undistortion, depth lookup
  PercentileSummary tracking_ms;  // pose estimation and local-map tracking
  PercentileSummary keyframe_ms;  // keyframe insertion, upload and the rest of the frame
};

// What the map went through.
struct MapCounters {
  std::uint64_t loops = 0;
  // Loops that joined two parts of the map (a map started after tracking was lost for good, met
  // again): in local mode every one, in edge mode those that moved this client's part.
  std::uint64_t merges = 0;
  // The frames at both ends of each loop (edge mode: of this client's loops).
  std::vector<LoopFramesRecord> loop_frames;
  // Monocular: median scene depth of the last quarter of the keyframes over that of the first
  // quarter (0 when there are too few keyframes). Along a drive the scene's depth stays about the
  // same, so a map whose scale drifts shows it here (a cheap hint, no ground truth needed).
  double keyframe_depth_ratio = 0.0;
};

// How many of the maps started after tracking was lost for good (at these frames) a loop tied back
// to a place seen before their start: a loop from a frame at or after the start to one before it.
// A tie is what counts, whether the loop merged two separate parts or the parts had met already
// through tracking (a relocalisation or a shared point) and the loop corrected the seam.
inline std::size_t mapsTiedBack(const std::vector<std::size_t>& started_at,
                                const std::vector<LoopFramesRecord>& loops) {
  std::size_t tied = 0;
  for (const std::size_t start : started_at) {
    for (const LoopFramesRecord& loop : loops) {
      if (loop.current_frame >= start && loop.loop_frame < start) {
        ++tied;
        break;
      }
    }
  }
  return tied;
}

// Localisation through the edge (`--localize-only` in edge mode): the client's questions.
struct EdgeLocalizationCounters {
  std::uint64_t queries = 0;                 // sent
  std::uint64_t relocalization_queries = 0;  // of those, lost frames for the edge to relocalise
  std::uint64_t relocalized_by_edge = 0;     // answered with a pose
  std::uint64_t window_moves = 0;            // tracked frames' window updates answered
  PercentileSummary answer_ms;               // query sent -> its slice applied
};

struct SlamCounters {
  EdgeExchangeCounters exchange;
  SemanticCounters semantic;
  ClientStageSummary stages;
  // How long tracking waited for the back end, and how often the back end refused keyframes.
  BackendPacing backend;
  MapCounters map;
  EdgeLocalizationCounters localization;
};

}  // namespace edgeslam
