#pragma once
// Sample wire records for the net tests: every field set to something non-default, so a field
// lost in either direction of a conversion shows.
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "features/scale_levels.h"
#include "map/map_records.h"
#include "wire/wire_types.h"

namespace edgeslam::test {

inline SE3d samplePose(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return SE3d(q.normalized(), Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
}

inline std::uint64_t clientId(std::uint8_t origin, std::uint64_t local) {
  return (static_cast<std::uint64_t>(origin) << 56) | local;
}

// `n` keypoints; sizes follow the ORB convention unless `custom_sizes`.
inline KeyFrameRecord sampleKeyFrame(std::uint64_t id, int n, std::mt19937& rng,
                                     bool with_depth = true, bool custom_sizes = false) {
  std::uniform_real_distribution<float> coord(0.f, 640.f);
  std::uniform_real_distribution<float> angle(0.f, 360.f);
  std::uniform_int_distribution<int> octave(0, 7);
  std::uniform_int_distribution<int> byte(0, 255);
  KeyFrameRecord kf;
  kf.id = id;
  kf.frame_index = 1234 + id % 1000;
  kf.timestamp = 1311868164.363181;
  kf.T_cw = samplePose(rng);
  kf.parent = id - 1;
  kf.features.pyramid_levels = 8;
  kf.features.scale_factor = 1.2;
  kf.features.bf = 40.5f;
  const ScaleLevels scales(8, 1.2);
  kf.features.descriptors.create(n, 32, CV_8UC1);
  for (int i = 0; i < n; ++i) {
    cv::KeyPoint kp;
    kp.pt = {coord(rng), coord(rng) * 0.75f};
    kp.angle = angle(rng);
    kp.octave = octave(rng);
    kp.size = custom_sizes ? 7.f + static_cast<float>(i % 5)
                           : 31.f * static_cast<float>(scales.scale(kp.octave));
    kp.response = 1e-4f * static_cast<float>(i + 1);
    kf.features.keypoints.push_back(kp);
    for (int b = 0; b < 32; ++b) kf.features.descriptors.at<std::uint8_t>(i, b) = byte(rng);
    if (with_depth) {
      kf.features.depth.push_back(i % 3 == 0 ? -1.f : 0.5f + 0.01f * static_cast<float>(i));
      kf.features.right_u.push_back(i % 3 == 0 ? -1.f : kp.pt.x - 3.f);
    }
    kf.point_ids.push_back(i % 2 == 0 ? clientId(3, 100000 + i) : kInvalidId);
  }
  return kf;
}

inline MapPointRecord samplePoint(std::uint64_t id, std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 2.0);
  std::uniform_int_distribution<int> byte(0, 255);
  MapPointRecord p;
  p.id = id;
  p.position = {normal(rng), normal(rng), 3.0 + normal(rng)};
  p.normal = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  for (auto& b : p.descriptor) b = static_cast<std::uint8_t>(byte(rng));
  p.min_distance = 0.7f;
  p.max_distance = 5.25f;
  p.reference_keyframe = clientId(3, 7);
  for (std::uint32_t k = 0; k < 4; ++k) {
    p.observations.push_back({clientId(3, 5 + k), 17 * k + 2});
  }
  return p;
}

// The header of a 320 x 240 grey JPEG (the sample camera halved), padded with zeros to `size`:
// what the edge server reads before it accepts a keyframe image.
inline std::vector<std::uint8_t> sampleKeyFrameImage(std::size_t size = 0) {
  constexpr std::array<std::uint8_t, 17> kHeader{0xff, 0xd8, 0xff, 0xc0, 0x00, 0x0b,
                                                 8,    0x00, 0xf0, 0x01, 0x40, 0x01,
                                                 0x01, 0x11, 0x00, 0xff, 0xd9};
  std::vector<std::uint8_t> bytes(std::max(size, kHeader.size()), 0);
  std::copy(kHeader.begin(), kHeader.end(), bytes.begin());
  return bytes;
}

// The header of a 640 x 480 grey JPEG: an offloaded frame of the sample camera, as far as the
// edge server's checks read it.
inline std::vector<std::uint8_t> sampleFrameImage() {
  return {0xff, 0xd8, 0xff, 0xc0, 0x00, 0x0b, 8,    0x01, 0xe0,
          0x02, 0x80, 0x01, 0x01, 0x11, 0x00, 0xff, 0xd9};
}

inline KeyFrameUpload sampleUpload(std::uint64_t sequence, int keypoints, int new_points,
                                   std::mt19937& rng) {
  KeyFrameUpload u;
  u.sequence = sequence;
  u.keyframe = sampleKeyFrame(clientId(3, 1000 + sequence), keypoints, rng);
  for (int i = 0; i < new_points; ++i)
    u.new_points.push_back(samplePoint(clientId(3, 50000 + i), rng));
  u.image_encoding = "jpeg";
  u.image_bytes = sampleKeyFrameImage();
  u.acknowledged_slice = sequence > 1 ? sequence - 1 : 0;
  u.segmenter_nms = 0.7f;
  return u;
}

inline MapSlice sampleSlice(std::uint64_t sequence, std::mt19937& rng) {
  MapSlice s;
  s.sequence = sequence;
  s.upload_sequence = sequence + 2;
  s.processed_keyframe = clientId(3, 77);
  s.newest_keyframe = clientId(3, 79);
  s.full_resync = true;
  s.keyframes.push_back(sampleKeyFrame(clientId(0, 9), 20, rng, false));
  for (int i = 0; i < 5; ++i) s.points_upserted.push_back(samplePoint(clientId(0, 300 + i), rng));
  for (int i = 0; i < 3; ++i) {
    s.point_positions.push_back({clientId(3, 400 + i), samplePoint(1, rng).position});
  }
  s.points_erased = {clientId(3, 4), clientId(0, 5)};
  s.keyframe_poses.push_back({clientId(3, 8), samplePose(rng), clientId(3, 7)});
  s.keyframe_poses.push_back({clientId(0, 9), samplePose(rng), kInvalidId});
  s.keyframes_erased = {clientId(3, 2)};
  s.reference_keyframe = clientId(3, 8);
  s.reference_pose = samplePose(rng);
  s.masks.push_back({clientId(3, 8), 160, 120, "png/4", {0x89, 'P', 'N', 'G', 9}, 131.5});
  s.loops_closed = 2;
  s.maps_merged = 1;
  s.loops = {{512, 97}, {530, 440}};
  s.keyframes_evicted = {clientId(3, 5), clientId(3, 6), clientId(0, 1)};
  s.map_keyframes = 321;
  s.map_points = 45678;
  return s;
}

inline SessionConfig sampleSessionConfig(const std::string& name = "test-client") {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = 585.0;
  in.fy = 586.5;
  in.cx = 320.5;
  in.cy = 240.25;
  in.distortion = {0.1, -0.05, 0.001, -0.002, 0.01};
  in.depth_factor = 1000.0;
  in.fps = 30.0;
  SessionConfig config;
  config.client_name = name;
  config.camera = PinholeCamera(in);
  config.sensor = Sensor::kRgbd;
  config.settings = {1500, 6, 1.25, false, 35};
  return config;
}

}  // namespace edgeslam::test
