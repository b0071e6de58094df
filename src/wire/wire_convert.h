#pragma once
// Map records and session types <-> protobuf messages of proto/edgeslam/v1. Encoding fails only
// for records that cannot be represented (descriptors not N x 32 bytes...); decoding validates
// everything a peer could get wrong and throws WireError naming the element and field.
// Some values are quantised on the way (wire_packing.h, docs/wire.md): keypoint coordinates to
// 1/32 px, angles to 1/65536 turn, depths to 1 mm, point positions and keyframe poses of slices
// to float32, normals to int16 per component; right_u is rebuilt from depth when it follows it.
#include <cstddef>
#include <vector>

#include "edgeslam/v1/edgeslam.pb.h"
#include "edgeslam/v1/map_records.pb.h"
#include "map/map_records.h"
#include "wire/wire_error.h"
#include "wire/wire_types.h"

namespace edgeslam {

struct WireEncodeOptions {
  // Keypoint responses are not used after extraction; leave them out unless asked (4 bytes each).
  // Keypoint sizes travel only when they differ from the ORB convention 31 * scale^octave.
  bool keypoint_response = false;
  // The edge recomputes normal, descriptor and distance range of uploaded points from their
  // observations: uploads leave them out (44 bytes a point) unless asked.
  bool upload_point_appearance = false;
  // Bytes per keypoint angle: 1 (1.4-degree steps; ORB matching compares orientations in
  // 12-degree bins) or 2.
  int angle_bytes = 1;
  // Keyframe uploads: keypoints associated with a point the edge already has (not one of the
  // upload's new points) travel without their descriptor (32 bytes each); the edge takes the
  // point's. Off here so that a plain round trip is lossless; the client turns it on
  // (EdgeClientOptions::omit_known_point_descriptors).
  bool omit_known_point_descriptors = false;
};

void toProto(const SE3d& pose, v1::Pose* out);
void toProto(const KeyFrameRecord& keyframe, v1::KeyFrame* out, const WireEncodeOptions& = {});
// Points as columns; without appearance the normal, descriptor and distance range stay home.
void toProto(const std::vector<MapPointRecord>& points, v1::MapPoints* out, bool with_appearance);
void toProto(const std::vector<PointPositionRecord>& positions, v1::PointPositions* out);
void toProto(const std::vector<KeyFramePoseRecord>& poses, v1::KeyFramePoses* out);
void toProto(const KeyFrameUpload& upload, v1::KeyFrameUpload* out, const WireEncodeOptions& = {});
void toProto(const MaskRecord& mask, v1::Mask* out);
void toProto(const MapSlice& slice, v1::MapSlice* out, const WireEncodeOptions& = {});
// Fills client name, camera, sensor, settings and the preferred id origin (config.id_origin).
void toProto(const SessionConfig& config, v1::OpenSessionRequest* out);
void toProto(const OffloadFrame& frame, v1::OffloadFrameRequest* out);
void toProto(const OffloadResult& result, v1::OffloadFrameReply* out);

SE3d fromProto(const v1::Pose& pose);
// A keyframe of a slice: every descriptor present (one with descriptors left out, which only an
// upload may do, is a WireError).
KeyFrameRecord fromProto(const v1::KeyFrame& keyframe);
// Points sent without appearance decode with zero normal, descriptor and distance range.
std::vector<MapPointRecord> fromProto(const v1::MapPoints& points);
std::vector<PointPositionRecord> fromProto(const v1::PointPositions& positions);
std::vector<KeyFramePoseRecord> fromProto(const v1::KeyFramePoses& poses);
// Descriptors the upload left out decode as zero rows flagged in
// keyframe.features.descriptor_omitted (the edge fills them from its points).
KeyFrameUpload fromProto(const v1::KeyFrameUpload& upload);
MaskRecord fromProto(const v1::Mask& mask);
MapSlice fromProto(const v1::MapSlice& slice);
// Client name, camera (validated by PinholeCamera), sensor, settings; id_origin = the preference.
SessionConfig fromProto(const v1::OpenSessionRequest& request);
OffloadFrame fromProto(const v1::OffloadFrameRequest& request);
OffloadResult fromProto(const v1::OffloadFrameReply& reply);

// Serialized size in bytes, for uplink / downlink accounting and docs.
std::size_t wireSize(const google::protobuf::MessageLite& message);
std::size_t wireSize(const KeyFrameUpload& upload, const WireEncodeOptions& = {});
std::size_t wireSize(const MapSlice& slice, const WireEncodeOptions& = {});

}  // namespace edgeslam
