#pragma once
// Real 7-Scenes (redkitchen) frames for the map data tests: ORB features with depth, the
// ground-truth pose, extracted once per process and shared. Callers skip first when the data is
// absent (EDGESLAM_REQUIRE_SHARED).
#include <Eigen/Core>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "features/frame_features_builder.h"
#include "features/orb_extractor.h"
#include "geometry/camera.h"
#include "geometry/se3.h"
#include "support/shared_data.h"

namespace edgeslam::test {

inline const char* const kSevenScenesSequence = "datasets/7scenes-redkitchen-1000";

inline PinholeCamera sevenScenesCamera() {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 585.0;
  in.cx = 320.0;
  in.cy = 240.0;
  in.depth_factor = 1000.0;
  return PinholeCamera(in);
}

inline std::string sevenScenesFramePath(int index, const char* suffix) {
  char name[64];
  std::snprintf(name, sizeof(name), "/frame-%06d.%s", index, suffix);
  return sharedPath(kSevenScenesSequence).string() + name;
}

inline SE3d readSevenScenesCameraFromWorld(const std::string& path) {
  std::ifstream in(path);
  Eigen::Matrix4d T_wc;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!(in >> T_wc(r, c))) throw std::runtime_error("cannot read pose " + path);
    }
  }
  return SE3d::fromMatrix(T_wc).inverse();
}

// Millimetres to metres; 65535 (no depth) becomes 0.
inline cv::Mat readSevenScenesDepthMetres(const std::string& path) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (raw.empty() || raw.type() != CV_16UC1) throw std::runtime_error("cannot read depth " + path);
  cv::Mat metres;
  raw.convertTo(metres, CV_32FC1, 1.0 / 1000.0);
  metres.setTo(0.f, raw == 65535);
  return metres;
}

struct SevenScenesFrame {
  std::shared_ptr<const FrameFeatures> features;
  SE3d T_cw;
  cv::Mat depth;
};

inline const SevenScenesFrame& sevenScenesFrame(int index) {
  static std::map<int, SevenScenesFrame> cache;
  static const PinholeCamera camera = sevenScenesCamera();
  static OrbExtractor extractor;
  auto it = cache.find(index);
  if (it == cache.end()) {
    const std::string colour = sevenScenesFramePath(index, "color.jpg");
    const cv::Mat grey = cv::imread(colour, cv::IMREAD_GRAYSCALE);
    if (grey.empty()) throw std::runtime_error("cannot read " + colour);
    SevenScenesFrame frame;
    frame.depth = readSevenScenesDepthMetres(sevenScenesFramePath(index, "depth.png"));
    frame.features = buildFrameFeatures(grey, frame.depth, camera, extractor);
    frame.T_cw = readSevenScenesCameraFromWorld(sevenScenesFramePath(index, "pose.txt"));
    it = cache.emplace(index, std::move(frame)).first;
  }
  return it->second;
}

}  // namespace edgeslam::test
