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
#include "io/dataset_error.h"

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
  // True when right images are rectified to the left camera (KITTI); EuRoC's are raw.
  bool stereo_rectified = false;
  double fps = 0.0;  // nominal rate from timestamps or the dataset's documentation
};

// What load() decodes. A monocular run needs no depth: a 7-Scenes frame then takes ~3.8 ms here
// instead of ~11 ms with its depth PNG.
struct FrameContent {
  bool color = true;  // else only `gray` is kept (converted from the colour image all the same)
  bool depth = true;
  bool right = true;  // the stereo right image
};

class DatasetReader {
 public:
  virtual ~DatasetReader() = default;
  // Limits what later load() calls decode (everything by default); a reader that cannot leave a
  // part out decodes it anyway.
  void setContent(const FrameContent& content) { content_ = content; }
  const FrameContent& content() const { return content_; }
  virtual const DatasetInfo& info() const = 0;
  virtual const PinholeCamera& camera() const = 0;
  // Timestamps of all frames, known without loading images.
  virtual const std::vector<double>& timestamps() const = 0;
  // Ground truth (camera-to-world) of all frames, known without loading images; one entry per
  // frame, nullopt where the dataset has none for that frame.
  virtual const std::vector<std::optional<SE3d>>& groundTruth() const = 0;
  // Loads frame i (0 <= i < frame_count). Throws DatasetError naming the file on bad data.
  virtual DatasetFrame load(std::size_t index) = 0;

 protected:
  FrameContent content_;
};

struct DatasetOptions {
  DatasetFormat format = DatasetFormat::kAuto;
  // Overrides the dataset's own camera (the `--camera FILE.yaml` flag). Its size must match the
  // images. Fields it leaves at 0 (depth_factor, baseline_m, fps) keep the dataset's own values.
  std::optional<CameraIntrinsics> camera_override;
};

// Opens a dataset folder (or video file), detecting the format when asked to. Per format:
// - tum: rgb.txt, optional depth.txt (each rgb frame takes the nearest depth within 0.02 s; when
//   the dataset has depth, rgb frames without one are dropped), optional groundtruth.txt
//   (interpolated at each frame, see pose_interpolation.h). Camera: camera.yaml in the folder,
//   else the official Freiburg 1/2/3 calibration when the folder name, a README or the text files'
//   comments name it, else --camera is required. Depth factor 5000.
// - kitti: image_0/ (+ image_1/ = rectified stereo), times.txt, calib.txt (P0; baseline from P1),
//   poses.txt or ../poses/<seq>.txt or ../../poses/<seq>.txt. Image NNNNNN.png takes line NNNNNN
//   of times and poses, so an excerpt of a sequence can keep the full sequence's files.
// - euroc: mav0/cam0 (+ cam1, raw stereo paired by timestamp), sensor.yaml, ground truth
//   state_groundtruth_estimate0 (camera pose = T_WB * T_BS(cam0)).
// - 7scenes: frame-NNNNNN.{color.png|jpg, depth.png, pose.txt}, camera-intrinsics.txt; frame
//   number / 30 s; depth 65535 -> 0; non-finite pose files -> no ground truth for that frame.
// - images: image files in natural order + camera.yaml, optional times.txt and groundtruth.txt.
// - video: any file videoio decodes + <name>.yaml beside it; timestamps i / fps.
// All images are checked against the camera's size when loaded; errors name file (and line).
std::unique_ptr<DatasetReader> openDataset(const std::filesystem::path& path,
                                           const DatasetOptions& options = {});

// Which format a path holds, or throws DatasetError explaining what was looked for.
DatasetFormat detectDatasetFormat(const std::filesystem::path& path);

}  // namespace edgeslam
