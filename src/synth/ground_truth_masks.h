#pragma once
// Per-frame ground-truth masks of a generated dynamic sequence (`edgeslam synth-dynamic`):
// `masks.txt` in the dataset folder lists `timestamp masks/NNNNNN.png`, one line per frame in
// the order of rgb.txt; a mask is 8-bit, 255 on a pasted person, 0 elsewhere.
#include <cstddef>
#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace edgeslam {

class GroundTruthMasks {
 public:
  static constexpr const char* kListFile = "masks.txt";

  // nullopt when `dataset_dir` has no masks.txt (not a generated sequence). Throws DatasetError
  // naming file and line when masks.txt is malformed.
  static std::optional<GroundTruthMasks> open(const std::filesystem::path& dataset_dir);

  std::size_t size() const { return files_.size(); }
  const std::vector<double>& timestamps() const { return timestamps_; }

  // Mask of frame `index` (the dataset reader's frame index: every generated frame has depth, so
  // the TUM reader keeps them all, in this order). Throws DatasetError when the index is out of
  // range or the file is missing / not a single-channel image.
  cv::Mat1b load(std::size_t index) const;
  // Mask of the frame whose timestamp is within `tolerance_s` of `timestamp`; nullopt if none.
  std::optional<cv::Mat1b> loadAt(double timestamp, double tolerance_s = 0.001) const;

 private:
  std::filesystem::path list_;
  std::vector<double> timestamps_;
  std::vector<std::filesystem::path> files_;
};

// Convenience for one frame: nullopt when the folder has no masks.txt or no such frame.
std::optional<cv::Mat1b> loadGroundTruthMask(const std::filesystem::path& dataset_dir,
                                             std::size_t frame_index);

}  // namespace edgeslam
