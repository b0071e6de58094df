#pragma once
// One interface over every dataset format: frames in time order with images, depth, ground truth.
#include <cstddef>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/se3.h"

namespace edgeslam {

enum class DatasetFormat { kAuto, kTum, kKitti, kEuroc, kSevenScenes, kImages, kVideo };

std::string toString(DatasetFormat format);
// Accepts auto|tum|kitti|euroc|7scenes|images|video; throws std::invalid_argument otherwise.
DatasetFormat parseDatasetFormat(const std::string& name);

struct DatasetFrame {
  std::size_t index = 0;             // position in the sequence, 0-based
  double timestamp = 0.0;            // seconds
  std::string name;                  // file name (or frame number) for messages
  cv::Mat gray;                      // CV_8UC1, always present
  cv::Mat color;                     // CV_8UC3 BGR, empty when the dataset is grey only
  cv::Mat depth;                     // CV_32FC1 metres, 0 where invalid; empty when no depth
  cv::Mat right_gray;                // CV_8UC1 right stereo image; empty when not stereo
  std::optional<SE3d> ground_truth;  // camera-to-world, when the dataset has it for this frame
};

struct DatasetInfo {
  DatasetFormat format = DatasetFormat::kAuto;
  std::filesystem::path path;
  std::size_t frame_count = 0;
  bool has_depth = false;
  bool has_stereo = false;
  bool has_ground_truth = false;
  double fps = 0.0;  // nominal rate from timestamps or the dataset's documentation
};

class DatasetReader {
 public:
  virtual ~DatasetReader() = default;
  virtual const DatasetInfo& info() const = 0;
  virtual const PinholeCamera& camera() const = 0;
  // Timestamps of all frames, known without loading images.
  virtual const std::vector<double>& timestamps() const = 0;
  // Loads frame i (0 <= i < frame_count). Throws DatasetError naming the file on bad data.
  virtual DatasetFrame load(std::size_t index) = 0;
};

// Error with the offending file (and line, when a text file is malformed) in its message.
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DatasetOptions {
  DatasetFormat format = DatasetFormat::kAuto;
  // Overrides the dataset's own camera (the `--camera FILE.yaml` flag).
  std::optional<CameraIntrinsics> camera_override;
};

// Opens a dataset folder (or video file), detecting the format when asked to.
std::unique_ptr<DatasetReader> openDataset(const std::filesystem::path& path,
                                           const DatasetOptions& options = {});

// Which format a path holds, or throws DatasetError explaining what was looked for.
DatasetFormat detectDatasetFormat(const std::filesystem::path& path);

}  // namespace edgeslam
