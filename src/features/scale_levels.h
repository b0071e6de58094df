#pragma once
// Scale tables of an image pyramid: level l is the image shrunk by scale_factor^l. The tracker
// uses them to weight reprojection errors (inverse sigma^2) and to predict a point's level.
#include <vector>

namespace edgeslam {

class ScaleLevels {
 public:
  ScaleLevels() : ScaleLevels(8, 1.2) {}
  // Throws std::invalid_argument when num_levels < 1 or scale_factor <= 1 (or not finite).
  ScaleLevels(int num_levels, double scale_factor);

  int numLevels() const { return static_cast<int>(scale_.size()); }
  double scaleFactor() const { return scale_factor_; }
  double logScaleFactor() const { return log_scale_factor_; }

  // scale_factor^level, its inverse, its square (the variance of a keypoint's position in level-0
  // pixels, up to the unit sigma) and the inverse square.
  double scale(int level) const { return scale_[level]; }
  double invScale(int level) const { return inv_scale_[level]; }
  double sigma2(int level) const { return sigma2_[level]; }
  double invSigma2(int level) const { return inv_sigma2_[level]; }
  const std::vector<double>& scales() const { return scale_; }
  const std::vector<double>& invScales() const { return inv_scale_; }
  const std::vector<double>& sigma2s() const { return sigma2_; }
  const std::vector<double>& invSigma2s() const { return inv_sigma2_; }

  // Level at which a feature seen at level `reference_level` from distance `reference_distance`
  // is expected when seen from `distance`, clamped to the valid levels.
  int predictLevel(double reference_distance, int reference_level, double distance) const;

 private:
  double scale_factor_ = 1.2;
  double log_scale_factor_ = 0.0;
  std::vector<double> scale_, inv_scale_, sigma2_, inv_sigma2_;
};

}  // namespace edgeslam
