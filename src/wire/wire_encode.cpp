#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_set>

#include "features/scale_levels.h"
#include "wire/wire_convert.h"
#include "wire/wire_limits.h"
#include "wire/wire_packing.h"

namespace edgeslam {
namespace {

using namespace wire_packing;

constexpr float kOrbPatchSize = 31.f;

bool sizesFollowOrbConvention(const KeyFrameFeaturesRecord& features) {
  if (features.pyramid_levels < 1 || !(features.scale_factor > 1.0)) return false;
  const ScaleLevels scales(features.pyramid_levels, features.scale_factor);
  for (const cv::KeyPoint& kp : features.keypoints) {
    if (kp.octave < 0 || kp.octave >= features.pyramid_levels) return false;
    if (kp.size != kOrbPatchSize * static_cast<float>(scales.scale(kp.octave))) return false;
  }
  return true;
}

// The RGB-D feature builder's rule: right_u = u - bf / depth where the depth is known, else -1.
bool rightUFollowsDepth(const KeyFrameFeaturesRecord& features) {
  if (features.right_u.empty() || features.depth.size() != features.keypoints.size()) return false;
  for (std::size_t i = 0; i < features.keypoints.size(); ++i) {
    const float d = features.depth[i];
    const float expected = d > 0.f ? features.keypoints[i].pt.x - features.bf / d : -1.f;
    if (features.right_u[i] != expected) return false;
  }
  return true;
}

int bytesFor(std::uint64_t max_value) {
  int bytes = 1;
  while (bytes < 8 && (max_value >> (8 * bytes)) != 0) ++bytes;
  return bytes;
}

std::int64_t quantiseCoordinate(float value, std::size_t index, char axis, KeyFrameId id) {
  if (!std::isfinite(value) || std::abs(value) > kMaxCoordinate) {
    throw WireError(fmt::format("keyframe {:#x}: keypoint {} has {} = {}, outside +-{} px", id,
                                index, axis, value, kMaxCoordinate));
  }
  return std::llround(static_cast<double>(value) * kCoordinateSteps);
}

void encodeKeyPoints(const KeyFrameFeaturesRecord& features, KeyFrameId id, v1::KeyPoints* out,
                     const WireEncodeOptions& options) {
  const std::vector<cv::KeyPoint>& keypoints = features.keypoints;
  const std::size_t n = keypoints.size();
  out->set_count(static_cast<std::uint32_t>(n));
  if (n == 0) return;
  std::vector<std::int64_t> xs(n);
  std::vector<std::int64_t> ys(n);
  std::string* angles = out->mutable_angle();
  std::string* octaves = out->mutable_octave();
  const int angle_bytes = options.angle_bytes;
  if (angle_bytes != 1 && angle_bytes != 2) {
    throw WireError(fmt::format("angle_bytes must be 1 or 2, got {}", angle_bytes));
  }
  out->set_angle_bytes(static_cast<std::uint32_t>(angle_bytes));
  const std::uint64_t angle_mask = angle_bytes == 1 ? 0xffu : 0xffffu;
  angles->reserve(static_cast<std::size_t>(angle_bytes) * n);
  octaves->reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const cv::KeyPoint& kp = keypoints[i];
    xs[i] = quantiseCoordinate(kp.pt.x, i, 'x', id);
    ys[i] = quantiseCoordinate(kp.pt.y, i, 'y', id);
    if (!std::isfinite(kp.angle)) {
      throw WireError(fmt::format("keyframe {:#x}: keypoint {} has angle {}", id, i, kp.angle));
    }
    const double degrees = std::fmod(static_cast<double>(kp.angle), 360.0);  // a direction
    const long steps = std::lround(degrees * angleStepsPerDegree(angle_bytes));
    putUnsigned(*angles, static_cast<std::uint64_t>(steps) & angle_mask, angle_bytes);
    if (kp.octave < 0 || kp.octave > 255) {
      throw WireError(fmt::format("keyframe {:#x}: keypoint {} has octave {}", id, i, kp.octave));
    }
    putUnsigned(*octaves, static_cast<std::uint64_t>(kp.octave), 1);
  }
  const bool ordered_by_octave = std::is_sorted(
      keypoints.begin(), keypoints.end(),
      [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.octave < b.octave; });
  if (ordered_by_octave) {
    octaves->clear();
    for (const cv::KeyPoint& kp : keypoints) {
      while (out->octave_runs_size() <= kp.octave) out->add_octave_runs(0);
      out->set_octave_runs(kp.octave, out->octave_runs(kp.octave) + 1);
    }
  }
  const auto [x_min, x_max] = std::minmax_element(xs.begin(), xs.end());
  const auto [y_min, y_max] = std::minmax_element(ys.begin(), ys.end());
  const int bytes =
      bytesFor(static_cast<std::uint64_t>(std::max(*x_max - *x_min, *y_max - *y_min)));
  out->set_x_origin(static_cast<std::int32_t>(*x_min));
  out->set_y_origin(static_cast<std::int32_t>(*y_min));
  out->set_coordinate_bytes(static_cast<std::uint32_t>(bytes));
  std::string* x = out->mutable_x();
  std::string* y = out->mutable_y();
  x->reserve(n * static_cast<std::size_t>(bytes));
  y->reserve(n * static_cast<std::size_t>(bytes));
  for (std::size_t i = 0; i < n; ++i) {
    putUnsigned(*x, static_cast<std::uint64_t>(xs[i] - *x_min), bytes);
    putUnsigned(*y, static_cast<std::uint64_t>(ys[i] - *y_min), bytes);
  }
  const int count = static_cast<int>(n);
  if (!sizesFollowOrbConvention(features)) {
    out->mutable_size()->Reserve(count);
    for (const cv::KeyPoint& kp : keypoints) out->add_size(kp.size);
  }
  if (options.keypoint_response) {
    out->mutable_response()->Reserve(count);
    for (const cv::KeyPoint& kp : keypoints) out->add_response(kp.response);
  }
}

bool depthFitsMillimetres(const std::vector<float>& depth) {
  return std::all_of(depth.begin(), depth.end(), [](float d) {
    if (!(d > 0.f)) return true;  // unknown
    const double steps = std::round(static_cast<double>(d) * kDepthStepsPerMetre);
    return steps >= 1.0 && steps <= kMaxDepthSteps;
  });
}

void encodeDepth(const KeyFrameFeaturesRecord& features, v1::KeyFrameFeatures* out) {
  if (features.depth.empty()) return;
  if (!depthFitsMillimetres(features.depth)) {
    out->mutable_depth()->Add(features.depth.begin(), features.depth.end());
    return;
  }
  std::string* mm = out->mutable_depth_mm();
  mm->reserve(2 * features.depth.size());
  for (const float d : features.depth) {
    const double steps = d > 0.f ? std::round(static_cast<double>(d) * kDepthStepsPerMetre) : 0.0;
    putUnsigned(*mm, static_cast<std::uint64_t>(steps), 2);
  }
}

// `omit`: per keypoint, whether its descriptor stays home (empty: none does). A row the record
// lacks (decoded from an upload that left it out, so all zeros until the edge fills it) must be
// one of those: the wire never carries such a row as if it were a descriptor.
void encodeFeatures(const KeyFrameFeaturesRecord& features, KeyFrameId id,
                    v1::KeyFrameFeatures* out, const WireEncodeOptions& options,
                    const std::vector<bool>& omit) {
  const std::size_t n = features.keypoints.size();
  const cv::Mat& desc = features.descriptors;
  if (n > 0 &&
      (desc.rows != static_cast<int>(n) ||
       desc.cols != static_cast<int>(wire_limits::kDescriptorBytes) || desc.type() != CV_8UC1)) {
    throw WireError(
        fmt::format("keyframe {:#x}: descriptors must be {} x 32 CV_8U, got {} x {} of type {}", id,
                    n, desc.rows, desc.cols, desc.type()));
  }
  if (!features.depth.empty() && features.depth.size() != n) {
    throw WireError(fmt::format("keyframe {:#x}: {} depth values for {} keypoints", id,
                                features.depth.size(), n));
  }
  if (!features.right_u.empty() && features.right_u.size() != n) {
    throw WireError(fmt::format("keyframe {:#x}: {} right_u values for {} keypoints", id,
                                features.right_u.size(), n));
  }
  const std::vector<bool>& missing = features.descriptor_omitted;
  if (!missing.empty() && missing.size() != n) {
    throw WireError(fmt::format("keyframe {:#x}: descriptor_omitted has {} flags for {} keypoints",
                                id, missing.size(), n));
  }
  encodeKeyPoints(features, id, out->mutable_keypoints(), options);
  std::string* bytes = out->mutable_descriptors();
  bytes->reserve(n * wire_limits::kDescriptorBytes);
  for (std::size_t row = 0; row < n; ++row) {
    const bool omitted = !omit.empty() && omit[row];
    if (omitted) continue;
    if (!missing.empty() && missing[row]) {
      throw WireError(fmt::format(
          "keyframe {:#x}: keypoint {} has no descriptor (left out on its way in) to send", id,
          row));
    }
    bytes->append(reinterpret_cast<const char*>(desc.ptr<std::uint8_t>(static_cast<int>(row))),
                  wire_limits::kDescriptorBytes);
  }
  encodeDepth(features, out);
  if (rightUFollowsDepth(features)) {
    out->set_right_u_from_depth(true);
  } else {
    out->mutable_right_u()->Add(features.right_u.begin(), features.right_u.end());
  }
  out->set_pyramid_levels(static_cast<std::uint32_t>(std::max(features.pyramid_levels, 0)));
  out->set_scale_factor(features.scale_factor);
  out->set_bf(features.bf);
}

void putPosition(std::string& out, const Eigen::Vector3d& position, std::uint64_t id) {
  for (int k = 0; k < 3; ++k) {
    const auto value = static_cast<float>(position[k]);
    if (!std::isfinite(value)) {
      throw WireError(fmt::format("map point {:#x}: position ({}, {}, {}) is not finite in float32",
                                  id, position.x(), position.y(), position.z()));
    }
    putFloat(out, value);
  }
}

void putNormal(std::string& out, const Eigen::Vector3d& normal) {
  const double norm = normal.norm();
  // A direction: travels normalised (a zero normal, not yet computed, stays zero).
  const Eigen::Vector3d unit =
      std::isfinite(norm) && norm > 0.0 ? Eigen::Vector3d(normal / norm) : Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const long steps = std::lround(std::clamp(unit[k], -1.0, 1.0) * kNormalSteps);
    putUnsigned(out, static_cast<std::uint64_t>(steps) & 0xffffu, 2);
  }
}

void putPose(std::string& out, const SE3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation();
  const Eigen::Vector3d& t = pose.translation();
  for (const double value : {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()}) {
    putFloat(out, static_cast<float>(value));
  }
}

}  // namespace

void toProto(const SE3d& pose, v1::Pose* out) {
  const Eigen::Quaterniond& q = pose.rotation();
  const Eigen::Vector3d& t = pose.translation();
  out->set_qw(q.w());
  out->set_qx(q.x());
  out->set_qy(q.y());
  out->set_qz(q.z());
  out->set_tx(t.x());
  out->set_ty(t.y());
  out->set_tz(t.z());
}

namespace {

// The keypoints whose descriptor an upload leaves out: those associated with a point that is not
// one of the upload's new points (the edge has it). Empty when there is none.
std::vector<bool> knownPointKeypoints(const KeyFrameUpload& upload) {
  std::unordered_set<MapPointId> new_ids;
  new_ids.reserve(upload.new_points.size());
  for (const MapPointRecord& point : upload.new_points) new_ids.insert(point.id);
  const std::vector<MapPointId>& point_ids = upload.keyframe.point_ids;
  std::vector<bool> known(point_ids.size(), false);
  bool any = false;
  for (std::size_t i = 0; i < point_ids.size(); ++i) {
    known[i] = point_ids[i] != kInvalidId && !new_ids.contains(point_ids[i]);
    any = any || known[i];
  }
  if (!any) known.clear();
  return known;
}

void encodeKeyFrame(const KeyFrameRecord& keyframe, v1::KeyFrame* out,
                    const WireEncodeOptions& options, const std::vector<bool>& omit) {
  out->set_id(keyframe.id);
  out->set_frame_index(keyframe.frame_index);
  out->set_timestamp(keyframe.timestamp);
  toProto(keyframe.T_cw, out->mutable_t_cw());
  out->set_parent(keyframe.parent);
  if (!keyframe.point_ids.empty() &&
      keyframe.point_ids.size() != keyframe.features.keypoints.size()) {
    throw WireError(fmt::format("keyframe {:#x}: {} point ids for {} keypoints", keyframe.id,
                                keyframe.point_ids.size(), keyframe.features.keypoints.size()));
  }
  encodeFeatures(keyframe.features, keyframe.id, out->mutable_features(), options, omit);
  out->set_known_point_descriptors_omitted(!omit.empty());
  std::size_t next_index = 0;
  std::uint64_t previous_id = keyframe.id;
  for (std::size_t i = 0; i < keyframe.point_ids.size(); ++i) {
    if (keyframe.point_ids[i] == kInvalidId) continue;
    out->add_point_keypoint_gaps(static_cast<std::uint32_t>(i - next_index));
    out->add_point_id_deltas(idDelta(keyframe.point_ids[i], previous_id));
    next_index = i + 1;
    previous_id = keyframe.point_ids[i];
  }
}

}  // namespace

void toProto(const KeyFrameRecord& keyframe, v1::KeyFrame* out, const WireEncodeOptions& options) {
  encodeKeyFrame(keyframe, out, options, {});
}

void toProto(const std::vector<MapPointRecord>& points, v1::MapPoints* out, bool with_appearance) {
  const std::size_t n = points.size();
  out->set_count(static_cast<std::uint32_t>(n));
  if (n == 0) return;
  const int count = static_cast<int>(n);
  out->mutable_id_deltas()->Reserve(count);
  out->mutable_reference_deltas()->Reserve(count);
  out->mutable_observation_counts()->Reserve(count);
  std::string* positions = out->mutable_positions();
  positions->reserve(12 * n);
  const bool any_from_depth = std::any_of(points.begin(), points.end(), [](const auto& point) {
    return point.position_from_depth && !point.observations.empty();
  });
  if (any_from_depth) out->mutable_positions_from_depth()->assign((n + 7) / 8, '\0');
  std::uint64_t previous_id = 0;
  std::uint64_t previous_first_keyframe = points.front().id;
  for (std::size_t i = 0; i < n; ++i) {
    const MapPointRecord& point = points[i];
    out->add_id_deltas(idDelta(point.id, previous_id));
    previous_id = point.id;
    if (any_from_depth && point.position_from_depth && !point.observations.empty()) {
      (*out->mutable_positions_from_depth())[i / 8] |= static_cast<char>(1u << (i % 8));
    } else {
      putPosition(*positions, point.position, point.id);
    }
    out->add_observation_counts(static_cast<std::uint32_t>(point.observations.size()));
    std::uint64_t previous_keyframe = previous_first_keyframe;
    for (const PointObservationRecord& obs : point.observations) {
      out->add_observation_keyframe_deltas(idDelta(obs.keyframe, previous_keyframe));
      out->add_observation_keypoints(obs.keypoint_index);
      previous_keyframe = obs.keyframe;
    }
    const std::uint64_t reference_base =
        point.observations.empty() ? point.id : point.observations.front().keyframe;
    if (!point.observations.empty()) previous_first_keyframe = point.observations.front().keyframe;
    out->add_reference_deltas(idDelta(point.reference_keyframe, reference_base));
  }
  if (!with_appearance) return;
  std::string* normals = out->mutable_normals();
  std::string* descriptors = out->mutable_descriptors();
  std::string* distances = out->mutable_distances();
  normals->reserve(6 * n);
  descriptors->reserve(wire_limits::kDescriptorBytes * n);
  distances->reserve(8 * n);
  for (const MapPointRecord& point : points) {
    putNormal(*normals, point.normal);
    descriptors->append(reinterpret_cast<const char*>(point.descriptor.data()),
                        point.descriptor.size());
    putFloat(*distances, point.min_distance);
    putFloat(*distances, point.max_distance);
  }
}

void toProto(const std::vector<PointPositionRecord>& positions, v1::PointPositions* out) {
  out->mutable_id_deltas()->Reserve(static_cast<int>(positions.size()));
  std::string* bytes = out->mutable_positions();
  bytes->reserve(12 * positions.size());
  std::uint64_t previous_id = 0;
  for (const PointPositionRecord& record : positions) {
    out->add_id_deltas(idDelta(record.id, previous_id));
    previous_id = record.id;
    putPosition(*bytes, record.position, record.id);
  }
}

void toProto(const std::vector<KeyFramePoseRecord>& poses, v1::KeyFramePoses* out) {
  out->mutable_id_deltas()->Reserve(static_cast<int>(poses.size()));
  out->mutable_parent_deltas()->Reserve(static_cast<int>(poses.size()));
  std::string* bytes = out->mutable_poses();
  bytes->reserve(4 * kPoseFloats * poses.size());
  std::uint64_t previous_id = 0;
  for (const KeyFramePoseRecord& record : poses) {
    out->add_id_deltas(idDelta(record.id, previous_id));
    previous_id = record.id;
    out->add_parent_deltas(idDelta(record.parent, record.id));
    putPose(*bytes, record.T_cw);
  }
}

void toProto(const KeyFrameUpload& upload, v1::KeyFrameUpload* out,
             const WireEncodeOptions& options) {
  out->set_sequence(upload.sequence);
  encodeKeyFrame(
      upload.keyframe, out->mutable_keyframe(), options,
      options.omit_known_point_descriptors ? knownPointKeypoints(upload) : std::vector<bool>{});
  if (!upload.new_points.empty()) {
    toProto(upload.new_points, out->mutable_new_points(), options.upload_point_appearance);
  }
  out->set_image_encoding(upload.image_encoding);
  out->set_image(upload.image_bytes.data(), upload.image_bytes.size());
  out->set_acknowledged_slice(upload.acknowledged_slice);
  out->set_map_reset(upload.map_reset);
  out->set_segmenter_nms(upload.segmenter_nms);
  out->set_localization_query(upload.localization_query);
}

void toProto(const MaskRecord& mask, v1::Mask* out) {
  out->set_keyframe(mask.keyframe);
  out->set_width(static_cast<std::uint32_t>(std::max(mask.width, 0)));
  out->set_height(static_cast<std::uint32_t>(std::max(mask.height, 0)));
  out->set_encoding(mask.encoding);
  out->set_data(mask.bytes.data(), mask.bytes.size());
  out->set_segmentation_ms(static_cast<float>(mask.segmentation_ms));
}

void toProto(const MapSlice& slice, v1::MapSlice* out, const WireEncodeOptions& options) {
  out->set_sequence(slice.sequence);
  out->set_upload_sequence(slice.upload_sequence);
  out->set_processed_keyframe(slice.processed_keyframe);
  out->set_newest_keyframe(slice.newest_keyframe);
  out->set_full_resync(slice.full_resync);
  out->mutable_keyframes()->Reserve(static_cast<int>(slice.keyframes.size()));
  for (const KeyFrameRecord& kf : slice.keyframes) toProto(kf, out->add_keyframes(), options);
  if (!slice.points_upserted.empty()) {
    toProto(slice.points_upserted, out->mutable_points_upserted(), /*with_appearance=*/true);
  }
  if (!slice.point_positions.empty()) {
    toProto(slice.point_positions, out->mutable_point_positions());
  }
  std::uint64_t previous = 0;
  for (const MapPointId id : slice.points_erased) {
    out->add_points_erased(idDelta(id, previous));
    previous = id;
  }
  if (!slice.keyframe_poses.empty()) toProto(slice.keyframe_poses, out->mutable_keyframe_poses());
  previous = 0;
  for (const KeyFrameId id : slice.keyframes_erased) {
    out->add_keyframes_erased(idDelta(id, previous));
    previous = id;
  }
  out->set_reference_keyframe(slice.reference_keyframe);
  if (slice.reference_pose) toProto(*slice.reference_pose, out->mutable_reference_pose());
  for (const MaskRecord& mask : slice.masks) toProto(mask, out->add_masks());
  out->set_loops_closed(slice.loops_closed);
  out->set_maps_merged(slice.maps_merged);
  for (const LoopFramesRecord& loop : slice.loops) {
    v1::LoopFrames* record = out->add_loops();
    record->set_current_frame(loop.current_frame);
    record->set_loop_frame(loop.loop_frame);
  }
  previous = 0;
  for (const KeyFrameId id : slice.keyframes_evicted) {
    out->add_keyframes_evicted(idDelta(id, previous));
    previous = id;
  }
  out->set_map_keyframes(slice.map_keyframes);
  out->set_map_points(slice.map_points);
  if (slice.localization) {
    const LocalizationAnswer& a = *slice.localization;
    v1::Localization* l = out->mutable_localization();
    l->set_frame_index(a.frame_index);
    l->set_found(a.found);
    l->set_keyframe(a.keyframe);
    if (a.T_cw) toProto(*a.T_cw, l->mutable_t_cw());
    l->set_inliers(a.inliers);
    l->set_candidates(a.candidates);
    l->set_edge_ms(static_cast<float>(a.edge_ms));
  }
}

void toProto(const SessionConfig& config, v1::OpenSessionRequest* out) {
  out->set_client_name(config.client_name);
  out->set_map_name(config.map_name);
  const CameraIntrinsics& in = config.camera.intrinsics();
  v1::Camera* camera = out->mutable_camera();
  camera->set_width(static_cast<std::uint32_t>(std::max(in.width, 0)));
  camera->set_height(static_cast<std::uint32_t>(std::max(in.height, 0)));
  camera->set_fx(in.fx);
  camera->set_fy(in.fy);
  camera->set_cx(in.cx);
  camera->set_cy(in.cy);
  camera->set_k1(in.distortion.k1);
  camera->set_k2(in.distortion.k2);
  camera->set_p1(in.distortion.p1);
  camera->set_p2(in.distortion.p2);
  camera->set_k3(in.distortion.k3);
  camera->set_baseline_m(in.baseline_m);
  camera->set_depth_factor(in.depth_factor);
  camera->set_fps(in.fps);
  switch (config.sensor) {
    case Sensor::kMonocular:
      out->set_sensor(v1::SENSOR_MONOCULAR);
      break;
    case Sensor::kRgbd:
      out->set_sensor(v1::SENSOR_RGBD);
      break;
    case Sensor::kStereo:
      out->set_sensor(v1::SENSOR_STEREO);
      break;
  }
  v1::SessionSettings* settings = out->mutable_settings();
  settings->set_features(static_cast<std::uint32_t>(std::max(config.settings.features, 0)));
  settings->set_pyramid_levels(
      static_cast<std::uint32_t>(std::max(config.settings.pyramid_levels, 0)));
  settings->set_scale_factor(config.settings.scale_factor);
  settings->set_semantic(config.settings.semantic);
  settings->set_client_map_keyframes(
      static_cast<std::uint32_t>(std::max(config.settings.client_map_keyframes, 0)));
  settings->set_localize_only(config.settings.localize_only);
  settings->set_frames_back_to_back(config.settings.frames_back_to_back);
  out->set_preferred_id_origin(config.id_origin);
}

void toProto(const OffloadFrame& frame, v1::OffloadFrameRequest* out) {
  out->set_frame_index(frame.frame_index);
  out->set_timestamp(frame.timestamp);
  out->set_image_encoding(frame.image_encoding);
  out->set_image(frame.image_bytes.data(), frame.image_bytes.size());
  out->set_depth_encoding(frame.depth_encoding);
  out->set_depth(frame.depth_bytes.data(), frame.depth_bytes.size());
}

void toProto(const OffloadResult& result, v1::OffloadFrameReply* out) {
  out->set_frame_index(result.frame_index);
  switch (result.state) {
    case OffloadTrackingState::kNotInitialized:
      out->set_state(v1::TRACKING_NOT_INITIALIZED);
      break;
    case OffloadTrackingState::kOk:
      out->set_state(v1::TRACKING_OK);
      break;
    case OffloadTrackingState::kLost:
      out->set_state(v1::TRACKING_LOST);
      break;
  }
  if (result.T_cw) toProto(*result.T_cw, out->mutable_t_cw());
  out->set_server_ms(result.server_ms);
  out->set_backend_wait_ms(result.backend_wait_ms);
}

std::size_t wireSize(const google::protobuf::MessageLite& message) {
  return message.ByteSizeLong();
}

std::size_t wireSize(const KeyFrameUpload& upload, const WireEncodeOptions& options) {
  v1::KeyFrameUpload message;
  toProto(upload, &message, options);
  return message.ByteSizeLong();
}

std::size_t wireSize(const MapSlice& slice, const WireEncodeOptions& options) {
  v1::MapSlice message;
  toProto(slice, &message, options);
  return message.ByteSizeLong();
}

}  // namespace edgeslam
