#pragma once
// A uniform grid over the undistorted image bounds holding keypoint indices, for fast window
// searches (projection matching, initialisation, stereo).
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "geometry/camera.h"

namespace edgeslam {

class FeatureGrid {
 public:
  FeatureGrid() = default;
  // Indexes `undistorted_keypoints` (positions in undistorted pixels, octave = level). Keypoints
  // outside `bounds` are kept in the nearest border cell, so no query ever misses one. Throws
  // std::invalid_argument for empty or non-finite bounds or cell_size <= 0.
  FeatureGrid(const PinholeCamera::Bounds& bounds,
              std::span<const cv::KeyPoint> undistorted_keypoints, double cell_size = 10.0);

  // Indices of the keypoints with |x - kp.x| <= radius and |y - kp.y| <= radius (a square
  // window, as projection search uses) and min_level <= octave <= max_level; a negative level
  // means no bound on that side. Order: by cell, then by index.
  std::vector<int> featuresInArea(float x, float y, float radius, int min_level = -1,
                                  int max_level = -1) const;
  // Same, into `out` (cleared first), to reuse its memory in tight loops.
  void featuresInArea(float x, float y, float radius, int min_level, int max_level,
                      std::vector<int>& out) const;

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  std::size_t size() const { return points_.size(); }

 private:
  int cellColumn(float x) const;
  int cellRow(float y) const;

  struct Entry {
    float x, y;
    int level;
    int index;
  };
  double min_x_ = 0.0, min_y_ = 0.0, inv_cell_ = 1.0;
  int cols_ = 0, rows_ = 0;
  std::vector<int> cell_start_;  // cols*rows + 1 offsets into points_ (compressed rows)
  std::vector<Entry> points_;    // grouped by cell
};

}  // namespace edgeslam
