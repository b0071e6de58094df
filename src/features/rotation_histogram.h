#pragma once
// Rotation consistency of a set of matches: between two views most correct matches share about the
// same change of keypoint angle. Angle differences are binned (30 bins of 12 degrees by default);
// matches outside the three fullest bins are the inconsistent ones.
#include <vector>

namespace edgeslam {

class RotationHistogram {
 public:
  // Throws std::invalid_argument when bins < 1.
  explicit RotationHistogram(int bins = 30);

  // Records match `id` whose keypoints have angles angle1 and angle2 (degrees).
  void add(float angle1_deg, float angle2_deg, int id);

  // Ids outside the fullest bins: the three fullest, the second and third only when they hold at
  // least `min_share` of the fullest one (a lone peak means a clear rotation).
  std::vector<int> inconsistent(double min_share = 0.1) const;
  // The complement: ids in the kept bins.
  std::vector<int> consistent(double min_share = 0.1) const;

 private:
  std::vector<bool> keptBins(double min_share) const;
  int binOf(float angle1_deg, float angle2_deg) const;

  std::vector<std::vector<int>> bins_;
};

}  // namespace edgeslam
