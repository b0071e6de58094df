#include "map/map_matching_internal.h"

#include <fmt/format.h>

#include <stdexcept>

namespace edgeslam::matching_detail {

void requireFeatures(const Frame& frame, const char* who) {
  if (frame.features == nullptr) {
    throw std::invalid_argument(fmt::format("{}: frame {} has no features", who, frame.index));
  }
  const std::size_t n = frame.features->size();
  if (frame.points.size() != n || frame.outliers.size() != n) {
    throw std::invalid_argument(
        fmt::format("{}: frame {} has {} keypoints but {} point slots and {} outlier flags", who,
                    frame.index, n, frame.points.size(), frame.outliers.size()));
  }
  if (n > 0 &&
      (frame.features->descriptors.rows != static_cast<int>(n) ||
       frame.features->descriptors.cols != 32 || frame.features->descriptors.type() != CV_8UC1)) {
    throw std::invalid_argument(
        fmt::format("{}: frame {} descriptors must be CV_8UC1 {}x32 (got {}x{})", who, frame.index,
                    n, frame.features->descriptors.rows, frame.features->descriptors.cols));
  }
}

const PinholeCamera& requireCamera(const Frame& frame, const char* who) {
  if (frame.camera == nullptr) {
    throw std::invalid_argument(fmt::format("{}: frame {} has no camera", who, frame.index));
  }
  return *frame.camera;
}

const SE3d& requirePose(const Frame& frame, const char* who) {
  if (!frame.T_cw.has_value()) {
    throw std::invalid_argument(
        fmt::format("{}: frame {} has no pose (T_cw must be set)", who, frame.index));
  }
  return *frame.T_cw;
}

std::vector<const MapPoint*> sortedUsablePoints(const std::vector<MapPoint*>& points) {
  std::vector<const MapPoint*> out;
  out.reserve(points.size());
  for (const MapPoint* p : points) {
    if (isUsable(p)) out.push_back(p);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

int removeRotationOutliers(const RotationHistogram& histogram, Frame& frame) {
  int removed = 0;
  for (const int index : histogram.inconsistent()) {
    frame.points[static_cast<std::size_t>(index)] = nullptr;
    ++removed;
  }
  return removed;
}

}  // namespace edgeslam::matching_detail
