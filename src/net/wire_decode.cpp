#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <string_view>
#include <unordered_set>

#include "features/scale_levels.h"
#include "net/wire_convert.h"
#include "net/wire_limits.h"

namespace edgeslam {
namespace {

constexpr float kOrbPatchSize = 31.f;
constexpr std::size_t kDescriptorBytes = wire_limits::kDescriptorBytes;

std::string idText(std::uint64_t id) {
  return fmt::format("{:#x}", id);
}

// Runs `decode` and prefixes any WireError with `where`, so the message names the whole path
// (upload 7: keyframe 0x100..05: keypoint 3: ...).
template <typename F>
auto within(const std::string& where, F&& decode) {
  try {
    return decode();
  } catch (const WireError& e) {
    throw WireError(fmt::format("{}: {}", where, e.what()));
  }
}

void requireFinite(double value, std::string_view field) {
  if (!std::isfinite(value)) throw WireError(fmt::format("{} is not finite ({})", field, value));
}

void requireId(std::uint64_t id, std::string_view field) {
  if (id == kInvalidId) throw WireError(fmt::format("{} is 0 (ids must be non-zero)", field));
}

void requireCount(std::size_t count, std::size_t limit, std::string_view what) {
  if (count > limit) {
    throw WireError(fmt::format("{} {} exceed the limit of {}", count, what, limit));
  }
}

Eigen::Vector3d decodeVector3(const google::protobuf::RepeatedField<double>& values,
                              std::string_view field) {
  if (values.size() != 3) {
    throw WireError(fmt::format("{} has {} values, expected 3", field, values.size()));
  }
  const Eigen::Vector3d v(values[0], values[1], values[2]);
  if (!v.allFinite()) throw WireError(fmt::format("{} is not finite", field));
  return v;
}

template <typename T>
void requireEmptyOrN(const google::protobuf::RepeatedField<T>& values, std::size_t n,
                     std::string_view field) {
  const auto size = static_cast<std::size_t>(values.size());
  if (size != 0 && size != n) {
    throw WireError(
        fmt::format("{} has {} values for {} keypoints (expected 0 or {})", field, size, n, n));
  }
}

template <typename T>
void requireN(const google::protobuf::RepeatedField<T>& values, std::size_t n,
              std::string_view field) {
  const auto size = static_cast<std::size_t>(values.size());
  if (size != n) {
    throw WireError(fmt::format("{} has {} values for {} keypoints", field, size, n));
  }
}

KeyFrameFeaturesRecord decodeFeatures(const v1::KeyFrameFeatures& in) {
  KeyFrameFeaturesRecord out;
  const v1::KeyPoints& kps = in.keypoints();
  const auto n = static_cast<std::size_t>(kps.x_size());
  requireCount(n, wire_limits::kMaxKeypoints, "keypoints");
  requireN(kps.y(), n, "keypoints.y");
  requireN(kps.angle(), n, "keypoints.angle");
  requireN(kps.octave(), n, "keypoints.octave");
  requireEmptyOrN(kps.size(), n, "keypoints.size");
  requireEmptyOrN(kps.response(), n, "keypoints.response");
  requireEmptyOrN(in.depth(), n, "depth");
  requireEmptyOrN(in.right_u(), n, "right_u");
  if (in.descriptors().size() != n * kDescriptorBytes) {
    throw WireError(fmt::format("descriptors hold {} bytes, expected 32 x {} keypoints = {}",
                                in.descriptors().size(), n, n * kDescriptorBytes));
  }
  if (in.pyramid_levels() < 1 ||
      in.pyramid_levels() > static_cast<std::uint32_t>(wire_limits::kMaxPyramidLevels)) {
    throw WireError(fmt::format("pyramid_levels {} outside 1..{}", in.pyramid_levels(),
                                wire_limits::kMaxPyramidLevels));
  }
  if (!std::isfinite(in.scale_factor()) || in.scale_factor() <= 1.0 || in.scale_factor() > 4.0) {
    throw WireError(fmt::format("scale_factor {} outside (1, 4]", in.scale_factor()));
  }
  requireFinite(in.bf(), "bf");
  if (in.bf() < 0.f) throw WireError(fmt::format("bf {} is negative", in.bf()));
  out.pyramid_levels = static_cast<int>(in.pyramid_levels());
  out.scale_factor = in.scale_factor();
  out.bf = in.bf();
  const ScaleLevels scales(out.pyramid_levels, out.scale_factor);

  out.keypoints.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int k = static_cast<int>(i);
    cv::KeyPoint& kp = out.keypoints[i];
    kp.pt = {kps.x(k), kps.y(k)};
    kp.angle = kps.angle(k);
    if (!std::isfinite(kp.pt.x) || !std::isfinite(kp.pt.y) || !std::isfinite(kp.angle)) {
      throw WireError(fmt::format("keypoint {} has a non-finite coordinate or angle", i));
    }
    if (kps.octave(k) >= in.pyramid_levels()) {
      throw WireError(fmt::format("keypoint {} has octave {} but the pyramid has {} levels", i,
                                  kps.octave(k), in.pyramid_levels()));
    }
    kp.octave = static_cast<int>(kps.octave(k));
    kp.size = kps.size_size() == 0 ? kOrbPatchSize * static_cast<float>(scales.scale(kp.octave))
                                   : kps.size(k);
    kp.response = kps.response_size() == 0 ? 0.f : kps.response(k);
    if (!std::isfinite(kp.size) || !std::isfinite(kp.response)) {
      throw WireError(fmt::format("keypoint {} has a non-finite size or response", i));
    }
  }
  out.descriptors.create(static_cast<int>(n), static_cast<int>(kDescriptorBytes), CV_8UC1);
  if (n > 0) std::memcpy(out.descriptors.data, in.descriptors().data(), n * kDescriptorBytes);
  out.depth.assign(in.depth().begin(), in.depth().end());
  out.right_u.assign(in.right_u().begin(), in.right_u().end());
  for (std::size_t i = 0; i < out.depth.size(); ++i) {
    if (std::isnan(out.depth[i])) throw WireError(fmt::format("depth of keypoint {} is NaN", i));
  }
  for (std::size_t i = 0; i < out.right_u.size(); ++i) {
    if (std::isnan(out.right_u[i])) {
      throw WireError(fmt::format("right_u of keypoint {} is NaN", i));
    }
  }
  return out;
}

std::vector<std::uint64_t> decodeIds(const google::protobuf::RepeatedField<std::uint64_t>& ids,
                                     std::size_t limit, std::string_view field) {
  requireCount(static_cast<std::size_t>(ids.size()), limit, field);
  std::vector<std::uint64_t> out(ids.begin(), ids.end());
  for (std::size_t i = 0; i < out.size(); ++i) {
    requireId(out[i], fmt::format("{}[{}]", field, i));
  }
  return out;
}

}  // namespace

SE3d fromProto(const v1::Pose& pose) {
  const Eigen::Quaterniond q(pose.qw(), pose.qx(), pose.qy(), pose.qz());
  const Eigen::Vector3d t(pose.tx(), pose.ty(), pose.tz());
  if (!q.coeffs().allFinite() || !t.allFinite()) throw WireError("pose is not finite");
  const double norm = q.norm();
  if (norm < 1e-6) {
    throw WireError(fmt::format("pose quaternion has norm {} and cannot be normalised", norm));
  }
  return SE3d(q, t);  // normalises
}

KeyFrameRecord fromProto(const v1::KeyFrame& in) {
  return within(fmt::format("keyframe {}", idText(in.id())), [&] {
    KeyFrameRecord out;
    requireId(in.id(), "id");
    out.id = in.id();
    out.frame_index = in.frame_index();
    requireFinite(in.timestamp(), "timestamp");
    out.timestamp = in.timestamp();
    if (!in.has_t_cw()) throw WireError("pose T_cw is missing");
    out.T_cw = within("T_cw", [&] { return fromProto(in.t_cw()); });
    out.parent = in.parent();
    out.features = decodeFeatures(in.features());
    const std::size_t n = out.features.keypoints.size();
    if (in.point_keypoint_index_size() != in.point_ids_size()) {
      throw WireError(fmt::format("{} point keypoint indices for {} point ids",
                                  in.point_keypoint_index_size(), in.point_ids_size()));
    }
    out.point_ids.assign(n, kInvalidId);
    for (int i = 0; i < in.point_ids_size(); ++i) {
      const std::uint32_t index = in.point_keypoint_index(i);
      if (index >= n) {
        throw WireError(fmt::format("point association {} names keypoint {} of {}", i, index, n));
      }
      requireId(in.point_ids(i), fmt::format("point_ids[{}]", i));
      if (out.point_ids[index] != kInvalidId) {
        throw WireError(fmt::format("keypoint {} is associated with two map points", index));
      }
      out.point_ids[index] = in.point_ids(i);
    }
    return out;
  });
}

MapPointRecord fromProto(const v1::MapPoint& in) {
  return within(fmt::format("map point {}", idText(in.id())), [&] {
    MapPointRecord out;
    requireId(in.id(), "id");
    out.id = in.id();
    out.position = decodeVector3(in.position(), "position");
    out.normal = decodeVector3(in.normal(), "normal");
    if (in.descriptor_bytes().size() != kDescriptorBytes) {
      throw WireError(
          fmt::format("descriptor holds {} bytes, expected 32", in.descriptor_bytes().size()));
    }
    std::memcpy(out.descriptor.data(), in.descriptor_bytes().data(), kDescriptorBytes);
    requireFinite(in.min_distance(), "min_distance");
    requireFinite(in.max_distance(), "max_distance");
    if (in.min_distance() < 0.f || in.max_distance() < 0.f) {
      throw WireError(
          fmt::format("distance range [{}, {}] is negative", in.min_distance(), in.max_distance()));
    }
    out.min_distance = in.min_distance();
    out.max_distance = in.max_distance();
    out.reference_keyframe = in.reference_keyframe();
    if (in.observation_keyframes_size() != in.observation_keypoints_size()) {
      throw WireError(fmt::format("{} observation keyframes for {} observation keypoints",
                                  in.observation_keyframes_size(),
                                  in.observation_keypoints_size()));
    }
    requireCount(static_cast<std::size_t>(in.observation_keyframes_size()),
                 wire_limits::kMaxObservations, "observations");
    out.observations.resize(static_cast<std::size_t>(in.observation_keyframes_size()));
    for (int i = 0; i < in.observation_keyframes_size(); ++i) {
      requireId(in.observation_keyframes(i), fmt::format("observation {} keyframe", i));
      if (in.observation_keypoints(i) >= wire_limits::kMaxKeypoints) {
        throw WireError(fmt::format("observation {} names keypoint {} (limit {})", i,
                                    in.observation_keypoints(i), wire_limits::kMaxKeypoints));
      }
      out.observations[static_cast<std::size_t>(i)] = {in.observation_keyframes(i),
                                                       in.observation_keypoints(i)};
    }
    return out;
  });
}

KeyFrameUpload fromProto(const v1::KeyFrameUpload& in) {
  return within(fmt::format("keyframe upload {}", in.sequence()), [&] {
    KeyFrameUpload out;
    if (in.sequence() == 0) throw WireError("sequence is 0 (sequences start at 1)");
    out.sequence = in.sequence();
    if (!in.has_keyframe()) throw WireError("keyframe is missing");
    out.keyframe = fromProto(in.keyframe());
    requireCount(static_cast<std::size_t>(in.new_points_size()), wire_limits::kMaxPointsPerMessage,
                 "new points");
    out.new_points.reserve(static_cast<std::size_t>(in.new_points_size()));
    for (const v1::MapPoint& point : in.new_points()) out.new_points.push_back(fromProto(point));
    const std::string& encoding = in.image_encoding();
    if (encoding.empty() != in.image().empty() ||
        !(encoding.empty() || encoding == "jpeg" || encoding == "png")) {
      throw WireError(fmt::format(
          "image encoding '{}' with {} image bytes (expected '' with none, or jpeg/png with some)",
          encoding, in.image().size()));
    }
    out.image_encoding = encoding;
    out.image_bytes.assign(in.image().begin(), in.image().end());
    out.acknowledged_slice = in.acknowledged_slice();
    return out;
  });
}

KeyFramePoseRecord fromProto(const v1::KeyFramePose& in) {
  return within(fmt::format("keyframe pose {}", idText(in.id())), [&] {
    KeyFramePoseRecord out;
    requireId(in.id(), "id");
    out.id = in.id();
    if (!in.has_t_cw()) throw WireError("pose T_cw is missing");
    out.T_cw = fromProto(in.t_cw());
    out.parent = in.parent();
    return out;
  });
}

MaskRecord fromProto(const v1::Mask& in) {
  return within(fmt::format("mask of keyframe {}", idText(in.keyframe())), [&] {
    MaskRecord out;
    requireId(in.keyframe(), "keyframe");
    out.keyframe = in.keyframe();
    const auto max_side = static_cast<std::uint32_t>(wire_limits::kMaxImageSide);
    if (in.width() < 1 || in.height() < 1 || in.width() > max_side || in.height() > max_side) {
      throw WireError(fmt::format("size {} x {} outside 1..{}", in.width(), in.height(), max_side));
    }
    if (in.encoding() != "png" && in.encoding() != "rle") {
      throw WireError(fmt::format("encoding '{}' is neither png nor rle", in.encoding()));
    }
    if (in.data().empty()) throw WireError("no data");
    out.width = static_cast<int>(in.width());
    out.height = static_cast<int>(in.height());
    out.encoding = in.encoding();
    out.bytes.assign(in.data().begin(), in.data().end());
    return out;
  });
}

MapSlice fromProto(const v1::MapSlice& in) {
  return within(fmt::format("map slice {}", in.sequence()), [&] {
    MapSlice out;
    if (in.sequence() == 0) throw WireError("sequence is 0 (sequences start at 1)");
    out.sequence = in.sequence();
    out.upload_sequence = in.upload_sequence();
    out.processed_keyframe = in.processed_keyframe();
    out.full_resync = in.full_resync();
    requireCount(static_cast<std::size_t>(in.keyframes_size()), wire_limits::kMaxKeyFramesPerSlice,
                 "keyframes");
    for (const v1::KeyFrame& kf : in.keyframes()) out.keyframes.push_back(fromProto(kf));
    requireCount(static_cast<std::size_t>(in.points_upserted_size()),
                 wire_limits::kMaxPointsPerMessage, "upserted points");
    out.points_upserted.reserve(static_cast<std::size_t>(in.points_upserted_size()));
    for (const v1::MapPoint& p : in.points_upserted()) out.points_upserted.push_back(fromProto(p));
    out.points_erased =
        decodeIds(in.points_erased(), wire_limits::kMaxErasedPerSlice, "points_erased");
    requireCount(static_cast<std::size_t>(in.keyframe_poses_size()),
                 wire_limits::kMaxKeyFramesPerSlice, "keyframe poses");
    for (const v1::KeyFramePose& p : in.keyframe_poses())
      out.keyframe_poses.push_back(fromProto(p));
    out.keyframes_erased =
        decodeIds(in.keyframes_erased(), wire_limits::kMaxErasedPerSlice, "keyframes_erased");
    out.reference_keyframe = in.reference_keyframe();
    if (in.has_reference_pose()) {
      out.reference_pose = within("reference pose", [&] { return fromProto(in.reference_pose()); });
    }
    requireCount(static_cast<std::size_t>(in.masks_size()), wire_limits::kMaxMasksPerSlice,
                 "masks");
    for (const v1::Mask& m : in.masks()) out.masks.push_back(fromProto(m));
    out.loops_closed = in.loops_closed();
    return out;
  });
}

SessionConfig fromProto(const v1::OpenSessionRequest& in) {
  return within("open session", [&] {
    SessionConfig out;
    if (in.client_name().size() > 256) throw WireError("client name longer than 256 characters");
    out.client_name = in.client_name();
    const v1::Camera& c = in.camera();
    const auto max_side = static_cast<std::uint32_t>(wire_limits::kMaxImageSide);
    if (c.width() > max_side || c.height() > max_side) {
      throw WireError(
          fmt::format("camera size {} x {} exceeds {}", c.width(), c.height(), max_side));
    }
    CameraIntrinsics intrinsics;
    intrinsics.width = static_cast<int>(c.width());
    intrinsics.height = static_cast<int>(c.height());
    intrinsics.fx = c.fx();
    intrinsics.fy = c.fy();
    intrinsics.cx = c.cx();
    intrinsics.cy = c.cy();
    intrinsics.distortion = {c.k1(), c.k2(), c.p1(), c.p2(), c.k3()};
    intrinsics.baseline_m = c.baseline_m();
    intrinsics.depth_factor = c.depth_factor();
    intrinsics.fps = c.fps();
    try {
      out.camera = PinholeCamera(intrinsics);
    } catch (const std::invalid_argument& e) {
      throw WireError(fmt::format("camera: {}", e.what()));
    }
    switch (in.sensor()) {
      case v1::SENSOR_MONOCULAR:
        out.sensor = Sensor::kMonocular;
        break;
      case v1::SENSOR_RGBD:
        out.sensor = Sensor::kRgbd;
        break;
      case v1::SENSOR_STEREO:
        out.sensor = Sensor::kStereo;
        break;
      default:
        throw WireError(
            fmt::format("sensor {} is not mono, rgbd or stereo", static_cast<int>(in.sensor())));
    }
    const v1::SessionSettings& s = in.settings();
    if (s.features() < 1 || s.features() > wire_limits::kMaxKeypoints) {
      throw WireError(fmt::format("settings.features {} outside 1..{}", s.features(),
                                  wire_limits::kMaxKeypoints));
    }
    if (s.pyramid_levels() < 1 ||
        s.pyramid_levels() > static_cast<std::uint32_t>(wire_limits::kMaxPyramidLevels)) {
      throw WireError(fmt::format("settings.pyramid_levels {} outside 1..{}", s.pyramid_levels(),
                                  wire_limits::kMaxPyramidLevels));
    }
    if (!std::isfinite(s.scale_factor()) || s.scale_factor() <= 1.0 || s.scale_factor() > 4.0) {
      throw WireError(fmt::format("settings.scale_factor {} outside (1, 4]", s.scale_factor()));
    }
    out.settings = {static_cast<int>(s.features()), static_cast<int>(s.pyramid_levels()),
                    s.scale_factor(), s.semantic()};
    if (in.preferred_id_origin() > 255) {
      throw WireError(fmt::format("preferred_id_origin {} exceeds 255", in.preferred_id_origin()));
    }
    out.id_origin = static_cast<std::uint8_t>(in.preferred_id_origin());
    return out;
  });
}

OffloadFrame fromProto(const v1::OffloadFrameRequest& in) {
  return within(fmt::format("offloaded frame {}", in.frame_index()), [&] {
    OffloadFrame out;
    out.frame_index = in.frame_index();
    requireFinite(in.timestamp(), "timestamp");
    out.timestamp = in.timestamp();
    if ((in.image_encoding() != "jpeg" && in.image_encoding() != "png") || in.image().empty()) {
      throw WireError(
          fmt::format("image encoding '{}' with {} bytes (expected jpeg or png, non-empty)",
                      in.image_encoding(), in.image().size()));
    }
    if (in.depth_encoding().empty() != in.depth().empty() ||
        !(in.depth_encoding().empty() || in.depth_encoding() == "png")) {
      throw WireError(fmt::format("depth encoding '{}' with {} bytes (expected '' or png)",
                                  in.depth_encoding(), in.depth().size()));
    }
    out.image_encoding = in.image_encoding();
    out.image_bytes.assign(in.image().begin(), in.image().end());
    out.depth_encoding = in.depth_encoding();
    out.depth_bytes.assign(in.depth().begin(), in.depth().end());
    return out;
  });
}

OffloadResult fromProto(const v1::OffloadFrameReply& in) {
  return within(fmt::format("offload reply {}", in.frame_index()), [&] {
    OffloadResult out;
    out.frame_index = in.frame_index();
    switch (in.state()) {
      case v1::TRACKING_NOT_INITIALIZED:
        out.state = OffloadTrackingState::kNotInitialized;
        break;
      case v1::TRACKING_OK:
        out.state = OffloadTrackingState::kOk;
        break;
      case v1::TRACKING_LOST:
        out.state = OffloadTrackingState::kLost;
        break;
      default:
        throw WireError(fmt::format("tracking state {} unknown", static_cast<int>(in.state())));
    }
    if (in.has_t_cw()) out.T_cw = fromProto(in.t_cw());
    if (out.state == OffloadTrackingState::kOk && !out.T_cw) {
      throw WireError("tracked but no pose");
    }
    requireFinite(in.server_ms(), "server_ms");
    out.server_ms = in.server_ms();
    return out;
  });
}

}  // namespace edgeslam
