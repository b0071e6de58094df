#pragma once
// Writes a sequence in the TUM RGB-D layout that `openDataset(..., auto)` reads back:
// rgb/NNNNNN.png + rgb.txt, depth/NNNNNN.png (uint16, `depth_factor` units per metre) + depth.txt,
// groundtruth.txt (camera-to-world, TUM), camera.yaml, and the ground-truth people masks
// masks/NNNNNN.png + masks.txt (see ground_truth_masks.h). Images are lossless PNG so that the
// frames equal their source outside the pasted people.
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/se3.h"
#include "io/trajectory.h"

namespace edgeslam {

class TumSequenceWriter {
 public:
  // `folder` must exist. `depth_factor` > 0 when the frames have depth.
  TumSequenceWriter(std::filesystem::path folder, std::string header, double depth_factor);

  // `image` CV_8UC3 or CV_8UC1; `depth_m` CV_32FC1 metres (0 = invalid) or empty; `mask` CV_8UC1.
  // Throws DatasetError naming the file that could not be written.
  void addFrame(double timestamp, const cv::Mat& image, const cv::Mat& depth_m,
                const cv::Mat1b& mask, const std::optional<SE3d>& camera_to_world);

  // Writes the text lists and camera.yaml.
  void finish(const CameraIntrinsics& camera);

 private:
  std::filesystem::path folder_;
  std::string header_;
  double depth_factor_;
  std::size_t frames_ = 0;
  std::string rgb_list_, depth_list_, mask_list_;
  Trajectory ground_truth_;
};

}  // namespace edgeslam
