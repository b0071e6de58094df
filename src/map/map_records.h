#pragma once
// Plain-data images of map elements, as they cross the wire between client and edge: no pointers,
// only ids. A keyframe upload goes client -> edge; a map slice goes edge -> client.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/se3.h"
#include "map/ids.h"

namespace edgeslam {

using Descriptor = std::array<std::uint8_t, 32>;

struct PointObservationRecord {
  KeyFrameId keyframe = kInvalidId;
  std::uint32_t keypoint_index = 0;
};

struct MapPointRecord {
  MapPointId id = kInvalidId;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  Descriptor descriptor{};
  float min_distance = 0.f;  // raw scale-invariance range (MapPoint applies its 0.8 / 1.2 margins)
  float max_distance = 0.f;
  KeyFrameId reference_keyframe = kInvalidId;
  std::vector<PointObservationRecord> observations;
  // Uploads only: the position is the back-projection of the first observation, a keypoint with
  // depth of the uploaded keyframe, so the wire leaves it out and the receiver rebuilds it
  // (rebuildPositionsFromDepth in map_replication.h).
  bool position_from_depth = false;
};

// A keyframe's features as extracted on the client: enough to rebuild its FrameFeatures on the
// other side (the grid is rebuilt from the session's camera).
struct KeyFrameFeaturesRecord {
  std::vector<cv::KeyPoint> keypoints;  // undistorted, octave = pyramid level
  cv::Mat descriptors;                  // N x 32 CV_8U
  // Decoded keyframe uploads only: per keypoint, true where the wire left the descriptor out (its
  // row is zero) because the keypoint's point is one the edge already has; the edge fills the row
  // from that point before the keyframe enters its map. Empty: every row present.
  std::vector<bool> descriptor_omitted;
  std::vector<float> depth;    // empty, or one per keypoint (<= 0 unknown)
  std::vector<float> right_u;  // empty, or one per keypoint
  int pyramid_levels = 8;
  double scale_factor = 1.2;
  float bf = 0.f;
};

struct KeyFrameRecord {
  KeyFrameId id = kInvalidId;
  std::uint64_t frame_index = 0;
  double timestamp = 0.0;
  SE3d T_cw;
  KeyFrameId parent = kInvalidId;
  KeyFrameFeaturesRecord features;
  std::vector<MapPointId> point_ids;  // per keypoint, kInvalidId where none
};

// Client -> edge: a new keyframe, the points the client created with it (RGB-D/stereo depth or
// local triangulation), and optionally the compressed image for segmentation.
struct KeyFrameUpload {
  std::uint64_t sequence = 0;  // per session, increasing
  bool map_reset = false;      // the client emptied its map before this keyframe (failed start)
  KeyFrameRecord keyframe;
  std::vector<MapPointRecord> new_points;
  std::string image_encoding;  // "" (none), "jpeg", "png"
  std::vector<std::uint8_t> image_bytes;
  // Not on the wire: the keyframe's image, encoded into image_bytes on the link's thread so that
  // tracking does not pay for the compression.
  cv::Mat raw_image;
  std::uint64_t acknowledged_slice = 0;  // last slice the client applied
  // Box NMS threshold nm for segmenting this and later keyframes (paper Table I); 0 = the edge's.
  float segmenter_nms = 0.f;
  // A localise-only client's question about the frame in `keyframe` (see LocalizationAnswer): with
  // keypoints and no parent, relocalise it; with a parent (the stored keyframe it tracks against),
  // move its map window there. The edge's map takes nothing from it.
  bool localization_query = false;
};

// A point that only moved: the receiver recomputes normal and distance range itself.
struct PointPositionRecord {
  MapPointId id = kInvalidId;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

struct KeyFramePoseRecord {
  KeyFrameId id = kInvalidId;
  SE3d T_cw;
  KeyFrameId parent = kInvalidId;
};

// A movable-object mask of a keyframe, compact: label image at reduced resolution, encoded.
struct MaskRecord {
  KeyFrameId keyframe = kInvalidId;
  int width = 0;  // of the encoded label image
  int height = 0;
  std::string encoding;  // "png/N" (reduced N times) or "empty" (see semantic/label_encoding.h)
  std::vector<std::uint8_t> bytes;
  double segmentation_ms = 0.0;  // the edge's time to segment the keyframe
};

// A loop closed between two keyframes of one client: the frames they were made at.
struct LoopFramesRecord {
  std::uint64_t current_frame = 0;
  std::uint64_t loop_frame = 0;
  bool operator==(const LoopFramesRecord&) const = default;
};

// Edge -> client: the answer to a localization_query upload.
struct LocalizationAnswer {
  std::uint64_t frame_index = 0;
  bool found = false;
  KeyFrameId keyframe = kInvalidId;  // the stored keyframe found against (the window's centre)
  std::optional<SE3d> T_cw;          // the frame's pose in the map, when relocalised
  std::uint32_t inliers = 0;
  std::uint32_t candidates = 0;  // keyframes tried
  double edge_ms = 0.0;
};

// Edge -> client: what changed in the global map since the last slice the client acknowledged.
struct MapSlice {
  std::uint64_t sequence = 0;         // per session, increasing
  std::uint64_t upload_sequence = 0;  // the keyframe upload this slice answers (0 = none)
  KeyFrameId processed_keyframe = kInvalidId;
  // The newest keyframe the edge had received when it built the slice: the observations a record
  // lacks in keyframes up to this one were dropped on the edge; newer ones it has not seen yet.
  KeyFrameId newest_keyframe = kInvalidId;
  bool full_resync = false;  // the client must drop its map and take this one
  // Keyframes the client does not hold: resync, edge-made, or back in the client's bounded window
  // (the points they see that the client lacks come in points_upserted).
  std::vector<KeyFrameRecord> keyframes;
  std::vector<MapPointRecord> points_upserted;
  std::vector<PointPositionRecord> point_positions;
  std::vector<MapPointId> points_erased;
  std::vector<KeyFramePoseRecord> keyframe_poses;
  std::vector<KeyFrameId> keyframes_erased;
  // Bounded client map: held keyframes that left the window around the client's latest keyframe.
  // The client drops their features and observations (and points no held keyframe sees) but keeps
  // their poses, which later slices still correct.
  std::vector<KeyFrameId> keyframes_evicted;
  KeyFrameId reference_keyframe = kInvalidId;
  std::optional<SE3d> reference_pose;  // T_cw of the reference keyframe after optimisation
  std::vector<MaskRecord> masks;
  std::uint32_t loops_closed = 0;  // loops closed on the edge since the last slice
  // Of those, loops that moved the part of the map this client was mapping in onto another part.
  std::uint32_t maps_merged = 0;
  // This client's loops closed since the last slice (both ends its keyframes).
  std::vector<LoopFramesRecord> loops;
  // Size of the edge's global map when the slice was built (0 = not said: an older edge).
  std::uint64_t map_keyframes = 0;
  std::uint64_t map_points = 0;
  std::optional<LocalizationAnswer> localization;  // answers a localization_query upload
};

}  // namespace edgeslam
