#pragma once
// A synthetic scene for the map matchers: random 3-D points with random descriptors, seen by
// cameras at chosen poses. Each view keeps the points that project inside the image, with the
// descriptor slightly perturbed and all keypoint angles alike, so the right match is known.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "features/frame_features.h"
#include "geometry/camera.h"
#include "geometry/se3.h"
#include "map/keyframe.h"
#include "map/map.h"

namespace edgeslam::test {

inline PinholeCamera syntheticCamera() {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 500.0;
  in.cx = 320.0;
  in.cy = 240.0;
  return PinholeCamera(in);
}

struct SyntheticView {
  std::shared_ptr<FrameFeatures> features;
  SE3d T_cw;
  std::vector<int> scene_point;  // scene point of each keypoint
};

inline std::shared_ptr<FrameFeatures> emptyFeatures(const PinholeCamera& camera) {
  auto features = std::make_shared<FrameFeatures>();
  features->descriptors = cv::Mat(0, 32, CV_8UC1);
  features->grid = FeatureGrid(camera.undistortedBounds(), features->keypoints);
  return features;
}

class SyntheticScene {
 public:
  // `count` points uniformly in a box 2..4 m in front of the origin camera.
  SyntheticScene(int count, std::uint32_t seed) : camera_(syntheticCamera()), rng_(seed) {
    std::uniform_real_distribution<double> xy(-1.5, 1.5), z(2.0, 4.0);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int i = 0; i < count; ++i) {
      // Drawn last coordinate first, the order this scene was tuned with (gcc evaluates call
      // arguments right to left, clang left to right): every compiler draws the same scene.
      const double pz = z(rng_);
      const double py = xy(rng_);
      const double px = xy(rng_);
      points_.emplace_back(px, py, pz);
      std::array<std::uint8_t, 32> d{};
      for (auto& b : d) b = static_cast<std::uint8_t>(byte(rng_));
      descriptors_.push_back(d);
    }
  }

  const PinholeCamera& camera() const { return camera_; }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }

  SyntheticView view(const SE3d& T_cw, int flipped_bits, bool with_depth) {
    SyntheticView out;
    out.T_cw = T_cw;
    auto features = std::make_shared<FrameFeatures>();
    std::vector<std::array<std::uint8_t, 32>> rows;
    std::uniform_int_distribution<int> bit(0, 255);
    std::normal_distribution<float> noise(0.f, 0.3f);
    for (std::size_t p = 0; p < points_.size(); ++p) {
      const Eigen::Vector3d pc = T_cw * points_[p];
      const auto px = camera_.project(pc);
      if (!px || px->x() < 5 || px->y() < 5 || px->x() > 634 || px->y() > 474) continue;
      const float angle_noise = noise(rng_);  // last argument first, as above
      const float y_noise = noise(rng_);
      const float x_noise = noise(rng_);
      cv::KeyPoint kp(static_cast<float>(px->x()) + x_noise, static_cast<float>(px->y()) + y_noise,
                      31.f, 45.f + angle_noise, 20.f, 0);
      features->keypoints.push_back(kp);
      auto d = descriptors_[p];
      for (int f = 0; f < flipped_bits; ++f) {
        const int b = bit(rng_);
        d[b / 8] ^= static_cast<std::uint8_t>(1u << (b % 8));
      }
      rows.push_back(d);
      if (with_depth) features->depth.push_back(static_cast<float>(pc.z()));
      out.scene_point.push_back(static_cast<int>(p));
    }
    features->descriptors = cv::Mat(static_cast<int>(rows.size()), 32, CV_8UC1);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      std::copy(rows[r].begin(), rows[r].end(),
                features->descriptors.ptr<std::uint8_t>(static_cast<int>(r)));
    }
    if (with_depth) {
      features->bf = static_cast<float>(camera_.fx()) * 0.08f;
      for (std::size_t i = 0; i < features->keypoints.size(); ++i) {
        features->right_u.push_back(features->keypoints[i].pt.x -
                                    features->bf / features->depth[i]);
      }
    }
    features->grid = FeatureGrid(camera_.undistortedBounds(), features->keypoints);
    out.features = std::move(features);
    return out;
  }

  // A keyframe for `view` with one map point per keypoint at the true scene position.
  KeyFrame* addKeyFrame(Map& map, const SyntheticView& view, std::size_t frame_index,
                        bool with_points) REQUIRES(map.updateMutex()) {
    KeyFrame* kf = map.createKeyFrame(frame_index, 0.0, view.features, view.T_cw);
    if (!with_points) return kf;
    for (std::size_t i = 0; i < view.scene_point.size(); ++i) {
      MapPoint* p = map.createMapPoint(points_[view.scene_point[i]], kf);
      map.addObservation(p, kf, i);
      map.refreshPoint(p);
      scene_of_[p] = view.scene_point[i];
    }
    return kf;
  }

  // Scene point a map point stands for, -1 when unknown.
  int sceneOf(const MapPoint* p) const {
    const auto it = scene_of_.find(p);
    return it == scene_of_.end() ? -1 : it->second;
  }

 private:
  PinholeCamera camera_;
  std::mt19937 rng_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<std::array<std::uint8_t, 32>> descriptors_;
  std::map<const MapPoint*, int> scene_of_;
};

// Camera at `center` (world) looking along +z, turned by `yaw` radians about y.
inline SE3d poseAt(const Eigen::Vector3d& center, double yaw = 0.0) {
  const Eigen::Matrix3d R_wc = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return SE3d(R_wc, center).inverse();
}

}  // namespace edgeslam::test
