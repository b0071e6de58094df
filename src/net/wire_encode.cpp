#include <fmt/format.h>

#include <cstring>

#include "features/scale_levels.h"
#include "net/wire_convert.h"
#include "net/wire_limits.h"

namespace edgeslam {
namespace {

constexpr float kOrbPatchSize = 31.f;

void setVector3(const Eigen::Vector3d& v, google::protobuf::RepeatedField<double>* out) {
  out->Reserve(3);
  for (int i = 0; i < 3; ++i) out->Add(v[i]);
}

bool sizesFollowOrbConvention(const KeyFrameFeaturesRecord& features) {
  if (features.pyramid_levels < 1 || !(features.scale_factor > 1.0)) return false;
  const ScaleLevels scales(features.pyramid_levels, features.scale_factor);
  for (const cv::KeyPoint& kp : features.keypoints) {
    if (kp.octave < 0 || kp.octave >= features.pyramid_levels) return false;
    if (kp.size != kOrbPatchSize * static_cast<float>(scales.scale(kp.octave))) return false;
  }
  return true;
}

void encodeFeatures(const KeyFrameFeaturesRecord& features, KeyFrameId id,
                    v1::KeyFrameFeatures* out, const WireEncodeOptions& options) {
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
  v1::KeyPoints* kps = out->mutable_keypoints();
  const int count = static_cast<int>(n);
  kps->mutable_x()->Reserve(count);
  kps->mutable_y()->Reserve(count);
  kps->mutable_angle()->Reserve(count);
  kps->mutable_octave()->Reserve(count);
  for (const cv::KeyPoint& kp : features.keypoints) {
    kps->add_x(kp.pt.x);
    kps->add_y(kp.pt.y);
    kps->add_angle(kp.angle);
    kps->add_octave(static_cast<std::uint32_t>(std::max(kp.octave, 0)));
  }
  if (!sizesFollowOrbConvention(features)) {
    kps->mutable_size()->Reserve(count);
    for (const cv::KeyPoint& kp : features.keypoints) kps->add_size(kp.size);
  }
  if (options.keypoint_response) {
    kps->mutable_response()->Reserve(count);
    for (const cv::KeyPoint& kp : features.keypoints) kps->add_response(kp.response);
  }
  std::string* bytes = out->mutable_descriptors();
  bytes->resize(n * wire_limits::kDescriptorBytes);
  for (int row = 0; row < count; ++row) {
    std::memcpy(bytes->data() + static_cast<std::size_t>(row) * wire_limits::kDescriptorBytes,
                desc.ptr<std::uint8_t>(row), wire_limits::kDescriptorBytes);
  }
  out->mutable_depth()->Add(features.depth.begin(), features.depth.end());
  out->mutable_right_u()->Add(features.right_u.begin(), features.right_u.end());
  out->set_pyramid_levels(static_cast<std::uint32_t>(std::max(features.pyramid_levels, 0)));
  out->set_scale_factor(features.scale_factor);
  out->set_bf(features.bf);
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

void toProto(const KeyFrameRecord& keyframe, v1::KeyFrame* out, const WireEncodeOptions& options) {
  out->set_id(keyframe.id);
  out->set_frame_index(keyframe.frame_index);
  out->set_timestamp(keyframe.timestamp);
  toProto(keyframe.T_cw, out->mutable_t_cw());
  out->set_parent(keyframe.parent);
  encodeFeatures(keyframe.features, keyframe.id, out->mutable_features(), options);
  if (!keyframe.point_ids.empty() &&
      keyframe.point_ids.size() != keyframe.features.keypoints.size()) {
    throw WireError(fmt::format("keyframe {:#x}: {} point ids for {} keypoints", keyframe.id,
                                keyframe.point_ids.size(), keyframe.features.keypoints.size()));
  }
  for (std::size_t i = 0; i < keyframe.point_ids.size(); ++i) {
    if (keyframe.point_ids[i] == kInvalidId) continue;
    out->add_point_keypoint_index(static_cast<std::uint32_t>(i));
    out->add_point_ids(keyframe.point_ids[i]);
  }
}

void toProto(const MapPointRecord& point, v1::MapPoint* out) {
  out->set_id(point.id);
  setVector3(point.position, out->mutable_position());
  setVector3(point.normal, out->mutable_normal());
  out->set_descriptor_bytes(point.descriptor.data(), point.descriptor.size());
  out->set_min_distance(point.min_distance);
  out->set_max_distance(point.max_distance);
  out->set_reference_keyframe(point.reference_keyframe);
  const int count = static_cast<int>(point.observations.size());
  out->mutable_observation_keyframes()->Reserve(count);
  out->mutable_observation_keypoints()->Reserve(count);
  for (const PointObservationRecord& obs : point.observations) {
    out->add_observation_keyframes(obs.keyframe);
    out->add_observation_keypoints(obs.keypoint_index);
  }
}

void toProto(const KeyFrameUpload& upload, v1::KeyFrameUpload* out,
             const WireEncodeOptions& options) {
  out->set_sequence(upload.sequence);
  toProto(upload.keyframe, out->mutable_keyframe(), options);
  out->mutable_new_points()->Reserve(static_cast<int>(upload.new_points.size()));
  for (const MapPointRecord& point : upload.new_points) toProto(point, out->add_new_points());
  out->set_image_encoding(upload.image_encoding);
  out->set_image(upload.image_bytes.data(), upload.image_bytes.size());
  out->set_acknowledged_slice(upload.acknowledged_slice);
}

void toProto(const KeyFramePoseRecord& pose, v1::KeyFramePose* out) {
  out->set_id(pose.id);
  toProto(pose.T_cw, out->mutable_t_cw());
  out->set_parent(pose.parent);
}

void toProto(const MaskRecord& mask, v1::Mask* out) {
  out->set_keyframe(mask.keyframe);
  out->set_width(static_cast<std::uint32_t>(std::max(mask.width, 0)));
  out->set_height(static_cast<std::uint32_t>(std::max(mask.height, 0)));
  out->set_encoding(mask.encoding);
  out->set_data(mask.bytes.data(), mask.bytes.size());
}

void toProto(const MapSlice& slice, v1::MapSlice* out, const WireEncodeOptions& options) {
  out->set_sequence(slice.sequence);
  out->set_upload_sequence(slice.upload_sequence);
  out->set_processed_keyframe(slice.processed_keyframe);
  out->set_full_resync(slice.full_resync);
  out->mutable_keyframes()->Reserve(static_cast<int>(slice.keyframes.size()));
  for (const KeyFrameRecord& kf : slice.keyframes) toProto(kf, out->add_keyframes(), options);
  out->mutable_points_upserted()->Reserve(static_cast<int>(slice.points_upserted.size()));
  for (const MapPointRecord& p : slice.points_upserted) toProto(p, out->add_points_upserted());
  out->mutable_points_erased()->Add(slice.points_erased.begin(), slice.points_erased.end());
  out->mutable_keyframe_poses()->Reserve(static_cast<int>(slice.keyframe_poses.size()));
  for (const KeyFramePoseRecord& p : slice.keyframe_poses) toProto(p, out->add_keyframe_poses());
  out->mutable_keyframes_erased()->Add(slice.keyframes_erased.begin(),
                                       slice.keyframes_erased.end());
  out->set_reference_keyframe(slice.reference_keyframe);
  if (slice.reference_pose) toProto(*slice.reference_pose, out->mutable_reference_pose());
  for (const MaskRecord& mask : slice.masks) toProto(mask, out->add_masks());
  out->set_loops_closed(slice.loops_closed);
}

void toProto(const SessionConfig& config, v1::OpenSessionRequest* out) {
  out->set_client_name(config.client_name);
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
