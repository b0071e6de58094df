#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>
#include <unordered_set>

#include "features/scale_levels.h"
#include "wire/wire_convert.h"
#include "wire/wire_limits.h"
#include "wire/wire_packing.h"

namespace edgeslam {
namespace {

using namespace wire_packing;

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
              std::string_view field, std::string_view what) {
  const auto size = static_cast<std::size_t>(values.size());
  if (size != n) throw WireError(fmt::format("{} has {} values for {} {}", field, size, n, what));
}

std::vector<cv::KeyPoint> decodeKeyPoints(const v1::KeyPoints& in, const ScaleLevels& scales) {
  const std::size_t n = in.count();
  requireCount(n, wire_limits::kMaxKeypoints, "keypoints");
  const std::uint32_t width = in.coordinate_bytes();
  if (n > 0 && (width < 1 || width > 4)) {
    throw WireError(fmt::format("keypoints.coordinate_bytes {} outside 1..4", width));
  }
  const Column x(in.x(), n, static_cast<int>(width), "keypoints.x");
  const Column y(in.y(), n, static_cast<int>(width), "keypoints.y");
  const std::uint32_t angle_bytes = in.angle_bytes() == 0 ? 2 : in.angle_bytes();
  if (angle_bytes != 1 && angle_bytes != 2) {
    throw WireError(fmt::format("keypoints.angle_bytes {} is neither 1 nor 2", in.angle_bytes()));
  }
  const Column angle(in.angle(), n, static_cast<int>(angle_bytes), "keypoints.angle");
  const double angle_steps_per_degree = angleStepsPerDegree(static_cast<int>(angle_bytes));
  const bool octave_runs = in.octave_runs_size() > 0;
  if (octave_runs && !in.octave().empty()) {
    throw WireError("keypoints carry both octave and octave_runs");
  }
  const Column octave(in.octave(), octave_runs ? 0 : n, 1, "keypoints.octave");
  std::vector<std::uint32_t> run_octaves;
  if (octave_runs) {
    if (in.octave_runs_size() > scales.numLevels()) {
      throw WireError(fmt::format("keypoints.octave_runs has {} levels but the pyramid has {}",
                                  in.octave_runs_size(), scales.numLevels()));
    }
    std::uint64_t total = 0;
    for (const std::uint32_t run : in.octave_runs()) total += run;
    if (total != n) {
      throw WireError(fmt::format("keypoints.octave_runs add up to {} for {} keypoints", total, n));
    }
    run_octaves.reserve(n);
    for (int level = 0; level < in.octave_runs_size(); ++level) {
      run_octaves.insert(run_octaves.end(), in.octave_runs(level),
                         static_cast<std::uint32_t>(level));
    }
  }
  requireEmptyOrN(in.size(), n, "keypoints.size");
  requireEmptyOrN(in.response(), n, "keypoints.response");
  std::vector<cv::KeyPoint> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    cv::KeyPoint& kp = out[i];
    const auto k = static_cast<int>(i);
    // int64: origin + a 4-byte value cannot overflow.
    kp.pt.x = static_cast<float>(
        static_cast<double>(in.x_origin() + static_cast<std::int64_t>(x.unsignedAt(i))) /
        kCoordinateSteps);
    kp.pt.y = static_cast<float>(
        static_cast<double>(in.y_origin() + static_cast<std::int64_t>(y.unsignedAt(i))) /
        kCoordinateSteps);
    kp.angle =
        static_cast<float>(static_cast<double>(angle.unsignedAt(i)) / angle_steps_per_degree);
    const std::uint64_t level = octave_runs ? run_octaves[i] : octave.unsignedAt(i);
    if (level >= static_cast<std::uint64_t>(scales.numLevels())) {
      throw WireError(fmt::format("keypoint {} has octave {} but the pyramid has {} levels", i,
                                  level, scales.numLevels()));
    }
    kp.octave = static_cast<int>(level);
    kp.size = in.size_size() == 0 ? kOrbPatchSize * static_cast<float>(scales.scale(kp.octave))
                                  : in.size(k);
    kp.response = in.response_size() == 0 ? 0.f : in.response(k);
    if (!std::isfinite(kp.size) || !std::isfinite(kp.response)) {
      throw WireError(fmt::format("keypoint {} has a non-finite size or response", i));
    }
  }
  return out;
}

std::vector<float> decodeDepth(const v1::KeyFrameFeatures& in, std::size_t n) {
  if (!in.depth_mm().empty() && in.depth_size() != 0) {
    throw WireError("depth travels both as depth_mm and as floats");
  }
  if (in.depth_size() != 0) {
    requireN(in.depth(), n, "depth", "keypoints");
    std::vector<float> out(in.depth().begin(), in.depth().end());
    for (std::size_t i = 0; i < n; ++i) {
      if (std::isnan(out[i])) throw WireError(fmt::format("depth of keypoint {} is NaN", i));
    }
    return out;
  }
  if (in.depth_mm().empty()) return {};
  const Column mm(in.depth_mm(), n, 2, "depth_mm");
  std::vector<float> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint64_t steps = mm.unsignedAt(i);
    out[i] =
        steps == 0 ? -1.f : static_cast<float>(static_cast<double>(steps) / kDepthStepsPerMetre);
  }
  return out;
}

// Descriptors come last: which rows travel follows from the point associations. `omitted`: per
// keypoint, whether its row was left out (empty: none was); those decode as zero rows.
void decodeDescriptors(const std::string& bytes, const std::vector<bool>& omitted,
                       KeyFrameFeaturesRecord& out) {
  const std::size_t n = out.keypoints.size();
  std::size_t sent = n;
  if (!omitted.empty())
    sent -= static_cast<std::size_t>(std::count(omitted.begin(), omitted.end(), true));
  if (bytes.size() != sent * kDescriptorBytes) {
    if (omitted.empty()) {
      throw WireError(fmt::format("descriptors hold {} bytes, expected 32 x {} keypoints = {}",
                                  bytes.size(), n, n * kDescriptorBytes));
    }
    throw WireError(fmt::format(
        "descriptors hold {} bytes, expected 32 x {} keypoints = {} ({} of the {} keypoints "
        "name a point the edge has and travel without theirs)",
        bytes.size(), sent, sent * kDescriptorBytes, n - sent, n));
  }
  out.descriptors =
      cv::Mat::zeros(static_cast<int>(n), static_cast<int>(kDescriptorBytes), CV_8UC1);
  std::size_t next = 0;
  for (std::size_t row = 0; row < n; ++row) {
    if (!omitted.empty() && omitted[row]) continue;
    std::memcpy(out.descriptors.ptr<std::uint8_t>(static_cast<int>(row)),
                bytes.data() + next * kDescriptorBytes, kDescriptorBytes);
    ++next;
  }
  out.descriptor_omitted = omitted;
}

KeyFrameFeaturesRecord decodeFeatures(const v1::KeyFrameFeatures& in) {
  KeyFrameFeaturesRecord out;
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
  out.keypoints =
      decodeKeyPoints(in.keypoints(), ScaleLevels(out.pyramid_levels, out.scale_factor));
  const std::size_t n = out.keypoints.size();
  out.depth = decodeDepth(in, n);
  if (in.right_u_from_depth()) {
    if (in.right_u_size() != 0) throw WireError("right_u both sent and to be rebuilt from depth");
    if (out.depth.empty()) throw WireError("right_u to be rebuilt from depth, but no depth");
    out.right_u.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      const float d = out.depth[i];
      out.right_u[i] = d > 0.f ? out.keypoints[i].pt.x - out.bf / d : -1.f;
    }
  } else {
    requireEmptyOrN(in.right_u(), n, "right_u");
    out.right_u.assign(in.right_u().begin(), in.right_u().end());
    for (std::size_t i = 0; i < out.right_u.size(); ++i) {
      if (std::isnan(out.right_u[i])) {
        throw WireError(fmt::format("right_u of keypoint {} is NaN", i));
      }
    }
  }
  return out;
}

// A list of ids sent as deltas (the first to 0); every id non-zero.
std::vector<std::uint64_t> decodeIdDeltas(
    const google::protobuf::RepeatedField<std::int64_t>& deltas, std::size_t limit,
    std::string_view field) {
  requireCount(static_cast<std::size_t>(deltas.size()), limit, field);
  std::vector<std::uint64_t> out;
  out.reserve(static_cast<std::size_t>(deltas.size()));
  std::uint64_t previous = 0;
  for (const std::int64_t delta : deltas) {
    previous = applyIdDelta(previous, delta);
    requireId(previous, fmt::format("{}[{}]", field, out.size()));
    out.push_back(previous);
  }
  return out;
}

Eigen::Vector3d positionAt(const Column& column, std::size_t point) {
  const Eigen::Vector3d position(column.floatAt(3 * point), column.floatAt(3 * point + 1),
                                 column.floatAt(3 * point + 2));
  if (!position.allFinite()) throw WireError("position is not finite");
  return position;
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

namespace {

// `new_points`: the ids of the upload's new points, when the keyframe comes in an upload (whose
// keypoints naming other points may travel without their descriptor); nullptr elsewhere.
KeyFrameRecord decodeKeyFrame(const v1::KeyFrame& in,
                              const std::unordered_set<MapPointId>* new_points) {
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
    if (in.point_keypoint_gaps_size() != in.point_id_deltas_size()) {
      throw WireError(fmt::format("{} point keypoint gaps for {} point id deltas",
                                  in.point_keypoint_gaps_size(), in.point_id_deltas_size()));
    }
    out.point_ids.assign(n, kInvalidId);
    std::uint64_t next_index = 0;  // keypoints increase: none is associated twice
    std::uint64_t id = out.id;
    for (int i = 0; i < in.point_id_deltas_size(); ++i) {
      const std::uint64_t index = next_index + in.point_keypoint_gaps(i);
      if (index >= n) {
        throw WireError(fmt::format("point association {} names keypoint {} of {}", i, index, n));
      }
      id = applyIdDelta(id, in.point_id_deltas(i));
      requireId(id, fmt::format("point id of association {}", i));
      out.point_ids[index] = id;
      next_index = index + 1;
    }
    std::vector<bool> omitted;
    if (in.known_point_descriptors_omitted()) {
      if (new_points == nullptr) {
        throw WireError(
            "known_point_descriptors_omitted is set, but only a keyframe upload may leave "
            "descriptors out");
      }
      omitted.assign(n, false);
      bool any = false;
      for (std::size_t i = 0; i < n; ++i) {
        omitted[i] = out.point_ids[i] != kInvalidId && !new_points->contains(out.point_ids[i]);
        any = any || omitted[i];
      }
      if (!any) {
        throw WireError(
            "known_point_descriptors_omitted is set, but no keypoint names a point other than "
            "the upload's new points");
      }
    }
    decodeDescriptors(in.features().descriptors(), omitted, out.features);
    return out;
  });
}

}  // namespace

KeyFrameRecord fromProto(const v1::KeyFrame& in) {
  return decodeKeyFrame(in, nullptr);
}

std::vector<MapPointRecord> fromProto(const v1::MapPoints& in) {
  const std::size_t n = in.count();
  requireCount(n, wire_limits::kMaxPointsPerMessage, "points");
  requireN(in.id_deltas(), n, "points.id_deltas", "points");
  requireN(in.reference_deltas(), n, "points.reference_deltas", "points");
  requireN(in.observation_counts(), n, "points.observation_counts", "points");
  const std::string& from_depth = in.positions_from_depth();
  if (!from_depth.empty() && from_depth.size() != (n + 7) / 8) {
    throw WireError(fmt::format("points.positions_from_depth has {} bytes for {} points",
                                from_depth.size(), n));
  }
  const auto positionFromDepth = [&](std::size_t i) {
    return !from_depth.empty() &&
           ((static_cast<unsigned char>(from_depth[i / 8]) >> (i % 8)) & 1u) != 0;
  };
  std::size_t explicit_positions = 0;
  for (std::size_t i = 0; i < n; ++i) explicit_positions += positionFromDepth(i) ? 0 : 1;
  const Column positions(in.positions(), 3 * explicit_positions, 4, "points.positions");
  std::size_t next_position = 0;
  const bool with_appearance =
      !in.normals().empty() || !in.descriptors().empty() || !in.distances().empty();
  const Column normals(in.normals(), with_appearance ? 3 * n : 0, 2, "points.normals");
  const Column descriptors(in.descriptors(), with_appearance ? n : 0,
                           static_cast<int>(kDescriptorBytes), "points.descriptors");
  const Column distances(in.distances(), with_appearance ? 2 * n : 0, 4, "points.distances");
  std::uint64_t observations = 0;
  for (const std::uint32_t count : in.observation_counts()) {
    requireCount(count, wire_limits::kMaxObservations, "observations of a point");
    observations += count;
  }
  if (observations != static_cast<std::uint64_t>(in.observation_keyframe_deltas_size()) ||
      observations != static_cast<std::uint64_t>(in.observation_keypoints_size())) {
    throw WireError(fmt::format(
        "observation counts add up to {}, but {} observation keyframes and {} keypoints "
        "were sent",
        observations, in.observation_keyframe_deltas_size(), in.observation_keypoints_size()));
  }
  std::vector<MapPointRecord> out(n);
  std::uint64_t id = 0;
  std::uint64_t previous_first_keyframe = 0;
  int next_observation = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<int>(i);
    id = applyIdDelta(id, in.id_deltas(k));
    within(fmt::format("map point {}", idText(id)), [&] {
      MapPointRecord& point = out[i];
      requireId(id, "id");
      point.id = id;
      if (positionFromDepth(i)) {
        if (in.observation_counts(k) == 0) {
          throw WireError("position from depth but no observation to take it from");
        }
        point.position_from_depth = true;  // rebuilt by the receiver from the keyframe
      } else {
        point.position = positionAt(positions, next_position++);
      }
      if (with_appearance) {
        point.normal = Eigen::Vector3d(normals.int16At(3 * i), normals.int16At(3 * i + 1),
                                       normals.int16At(3 * i + 2)) /
                       kNormalSteps;
        std::memcpy(point.descriptor.data(), in.descriptors().data() + i * kDescriptorBytes,
                    kDescriptorBytes);
        point.min_distance = distances.floatAt(2 * i);
        point.max_distance = distances.floatAt(2 * i + 1);
        requireFinite(point.min_distance, "min_distance");
        requireFinite(point.max_distance, "max_distance");
        if (point.min_distance < 0.f || point.max_distance < 0.f) {
          throw WireError(fmt::format("distance range [{}, {}] is negative", point.min_distance,
                                      point.max_distance));
        }
      }
      point.observations.resize(in.observation_counts(k));
      if (i == 0) previous_first_keyframe = id;
      std::uint64_t keyframe = previous_first_keyframe;
      for (std::size_t j = 0; j < point.observations.size(); ++j, ++next_observation) {
        keyframe = applyIdDelta(keyframe, in.observation_keyframe_deltas(next_observation));
        requireId(keyframe, fmt::format("observation {} keyframe", j));
        const std::uint32_t keypoint = in.observation_keypoints(next_observation);
        if (keypoint >= wire_limits::kMaxKeypoints) {
          throw WireError(fmt::format("observation {} names keypoint {} (limit {})", j, keypoint,
                                      wire_limits::kMaxKeypoints));
        }
        point.observations[j] = {keyframe, keypoint};
      }
      const std::uint64_t reference_base =
          point.observations.empty() ? id : point.observations.front().keyframe;
      if (!point.observations.empty())
        previous_first_keyframe = point.observations.front().keyframe;
      point.reference_keyframe = applyIdDelta(reference_base, in.reference_deltas(k));
      return 0;
    });
  }
  return out;
}

std::vector<PointPositionRecord> fromProto(const v1::PointPositions& in) {
  const std::vector<std::uint64_t> ids =
      decodeIdDeltas(in.id_deltas(), wire_limits::kMaxPointsPerMessage, "point_positions ids");
  const Column positions(in.positions(), 3 * ids.size(), 4, "point_positions.positions");
  std::vector<PointPositionRecord> out(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    out[i].id = ids[i];
    out[i].position = within(fmt::format("moved point {}", idText(ids[i])),
                             [&] { return positionAt(positions, i); });
  }
  return out;
}

std::vector<KeyFramePoseRecord> fromProto(const v1::KeyFramePoses& in) {
  const std::vector<std::uint64_t> ids =
      decodeIdDeltas(in.id_deltas(), wire_limits::kMaxKeyFramesPerSlice, "keyframe_poses ids");
  requireN(in.parent_deltas(), ids.size(), "keyframe_poses.parent_deltas", "keyframe poses");
  const Column values(in.poses(), kPoseFloats * ids.size(), 4, "keyframe_poses.poses");
  std::vector<KeyFramePoseRecord> out(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) {
    out[i].id = ids[i];
    out[i].parent = applyIdDelta(ids[i], in.parent_deltas(static_cast<int>(i)));
    v1::Pose pose;
    const std::size_t base = kPoseFloats * i;
    pose.set_qw(values.floatAt(base));
    pose.set_qx(values.floatAt(base + 1));
    pose.set_qy(values.floatAt(base + 2));
    pose.set_qz(values.floatAt(base + 3));
    pose.set_tx(values.floatAt(base + 4));
    pose.set_ty(values.floatAt(base + 5));
    pose.set_tz(values.floatAt(base + 6));
    out[i].T_cw =
        within(fmt::format("keyframe pose {}", idText(ids[i])), [&] { return fromProto(pose); });
  }
  return out;
}

KeyFrameUpload fromProto(const v1::KeyFrameUpload& in) {
  return within(fmt::format("keyframe upload {}", in.sequence()), [&] {
    KeyFrameUpload out;
    if (in.sequence() == 0) throw WireError("sequence is 0 (sequences start at 1)");
    out.sequence = in.sequence();
    if (!in.has_keyframe()) throw WireError("keyframe is missing");
    out.new_points = within("new points", [&] { return fromProto(in.new_points()); });
    std::unordered_set<MapPointId> new_point_ids;
    new_point_ids.reserve(out.new_points.size());
    for (const MapPointRecord& point : out.new_points) new_point_ids.insert(point.id);
    out.keyframe = decodeKeyFrame(in.keyframe(), &new_point_ids);
    out.map_reset = in.map_reset();
    if (!(in.segmenter_nms() >= 0.f && in.segmenter_nms() <= 1.f)) {
      throw WireError(fmt::format("segmenter NMS threshold {} outside [0, 1]", in.segmenter_nms()));
    }
    out.segmenter_nms = in.segmenter_nms();
    out.localization_query = in.localization_query();
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

MaskRecord fromProto(const v1::Mask& in) {
  return within(fmt::format("mask of keyframe {}", idText(in.keyframe())), [&] {
    MaskRecord out;
    requireId(in.keyframe(), "keyframe");
    out.keyframe = in.keyframe();
    const auto max_side = static_cast<std::uint32_t>(wire_limits::kMaxImageSide);
    if (in.width() < 1 || in.height() < 1 || in.width() > max_side || in.height() > max_side) {
      throw WireError(fmt::format("size {} x {} outside 1..{}", in.width(), in.height(), max_side));
    }
    const std::string& encoding = in.encoding();
    const bool empty = encoding == "empty";
    int reduction = 0;
    if (!empty && (encoding.rfind("png/", 0) != 0 ||
                   std::sscanf(encoding.c_str() + 4, "%d", &reduction) != 1 || reduction < 1 ||
                   reduction > 64 || encoding != "png/" + std::to_string(reduction))) {
      throw WireError(fmt::format("encoding '{}' is neither png/N (N 1..64) nor empty", encoding));
    }
    if (empty != in.data().empty()) {
      throw WireError(fmt::format("encoding '{}' with {} data bytes", encoding, in.data().size()));
    }
    if (!std::isfinite(in.segmentation_ms()) || in.segmentation_ms() < 0.f) {
      throw WireError(fmt::format("segmentation time {} ms", in.segmentation_ms()));
    }
    out.segmentation_ms = in.segmentation_ms();
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
    out.newest_keyframe = in.newest_keyframe();
    out.points_upserted =
        within("upserted points", [&] { return fromProto(in.points_upserted()); });
    out.point_positions = fromProto(in.point_positions());
    out.points_erased =
        decodeIdDeltas(in.points_erased(), wire_limits::kMaxErasedPerSlice, "points_erased");
    out.keyframe_poses = fromProto(in.keyframe_poses());
    out.keyframes_erased =
        decodeIdDeltas(in.keyframes_erased(), wire_limits::kMaxErasedPerSlice, "keyframes_erased");
    out.reference_keyframe = in.reference_keyframe();
    if (in.has_reference_pose()) {
      out.reference_pose = within("reference pose", [&] { return fromProto(in.reference_pose()); });
    }
    requireCount(static_cast<std::size_t>(in.masks_size()), wire_limits::kMaxMasksPerSlice,
                 "masks");
    for (const v1::Mask& m : in.masks()) out.masks.push_back(fromProto(m));
    out.loops_closed = in.loops_closed();
    out.maps_merged = in.maps_merged();
    requireCount(static_cast<std::size_t>(in.loops_size()), wire_limits::kMaxLoopsPerSlice,
                 "loops");
    for (const v1::LoopFrames& loop : in.loops()) {
      out.loops.push_back({loop.current_frame(), loop.loop_frame()});
    }
    out.keyframes_evicted = decodeIdDeltas(in.keyframes_evicted(), wire_limits::kMaxErasedPerSlice,
                                           "keyframes_evicted");
    out.map_keyframes = in.map_keyframes();
    out.map_points = in.map_points();
    if (in.has_localization()) {
      const v1::Localization& l = in.localization();
      LocalizationAnswer a;
      a.frame_index = l.frame_index();
      a.found = l.found();
      a.keyframe = l.keyframe();
      if (a.found) requireId(a.keyframe, "localization.keyframe");
      if (l.has_t_cw()) {
        a.T_cw = within("localization pose", [&] { return fromProto(l.t_cw()); });
      }
      a.inliers = l.inliers();
      a.candidates = l.candidates();
      if (!std::isfinite(l.edge_ms()) || l.edge_ms() < 0.f) {
        throw WireError(fmt::format("localization time {} ms", l.edge_ms()));
      }
      a.edge_ms = l.edge_ms();
      out.localization = a;
    }
    return out;
  });
}

SessionConfig fromProto(const v1::OpenSessionRequest& in) {
  return within("open session", [&] {
    SessionConfig out;
    if (in.client_name().size() > 256) throw WireError("client name longer than 256 characters");
    out.client_name = in.client_name();
    if (in.map_name().size() > 256) throw WireError("map name longer than 256 characters");
    out.map_name = in.map_name();
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
    if (s.client_map_keyframes() > wire_limits::kMaxClientMapKeyFrames) {
      throw WireError(fmt::format("settings.client_map_keyframes {} exceeds {}",
                                  s.client_map_keyframes(), wire_limits::kMaxClientMapKeyFrames));
    }
    out.settings = {static_cast<int>(s.features()),
                    static_cast<int>(s.pyramid_levels()),
                    s.scale_factor(),
                    s.semantic(),
                    static_cast<int>(s.client_map_keyframes()),
                    s.localize_only(),
                    s.frames_back_to_back()};
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
    requireFinite(in.backend_wait_ms(), "backend_wait_ms");
    if (in.backend_wait_ms() < 0.0) {
      throw WireError(fmt::format("backend_wait_ms {} is negative", in.backend_wait_ms()));
    }
    out.backend_wait_ms = in.backend_wait_ms();
    return out;
  });
}

}  // namespace edgeslam
