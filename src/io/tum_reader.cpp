// TUM RGB-D: rgb.txt (+ depth.txt, groundtruth.txt). Rules:
// - depth: each rgb frame takes the depth image nearest in time when within 0.02 s (the TUM
//   benchmark's tolerance). When the dataset has depth, rgb frames with no depth that close are
//   dropped, so every frame of an RGB-D dataset has depth; without depth.txt, depth stays empty.
// - ground truth: interpolatePose with 0.02 s tolerance on each side (pose_interpolation.h).
// - camera: camera.yaml in the folder, else the official Freiburg 1/2/3 calibration recognised
//   from the folder name, a README, or the comments of rgb.txt / groundtruth.txt.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>

#include "io/camera_file.h"
#include "io/pose_interpolation.h"
#include "io/reader_support.h"
#include "io/readers.h"

namespace edgeslam::detail {
namespace {

constexpr double kDepthFactor = 5000.0;
constexpr double kAssociationTolerance = 0.02;

// Official calibration of the TUM RGB-D Kinects (colour camera), from the dataset's web page
// "File Formats -> Intrinsic Camera Calibration of the Kinect".
CameraIntrinsics freiburgCamera(int number) {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.depth_factor = kDepthFactor;
  in.fps = 30.0;
  if (number == 1) {
    in.fx = 517.306408, in.fy = 516.469215, in.cx = 318.643040, in.cy = 255.313989;
    in.distortion = {0.262383, -0.953104, -0.005358, 0.002628, 1.163314};
  } else if (number == 2) {
    in.fx = 520.908620, in.fy = 521.007327, in.cx = 325.141442, in.cy = 249.701764;
    in.distortion = {0.231222, -0.784899, -0.003257, -0.000105, 0.917205};
  } else {
    in.fx = 535.4, in.fy = 539.2, in.cx = 320.1, in.cy = 247.6;  // fr3: already undistorted
  }
  return in;
}

// Finds "freiburgN" or "frN" (N = 1..3, optional '_' or '-' before N, no digit after it; "fr" not
// preceded by a letter), case-insensitive.
std::optional<int> freiburgNumberIn(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const auto numberAt = [&](std::size_t pos) -> std::optional<int> {
    if (pos < text.size() && (text[pos] == '_' || text[pos] == '-')) ++pos;
    if (pos >= text.size() || text[pos] < '1' || text[pos] > '3') return std::nullopt;
    if (pos + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[pos + 1]))) {
      return std::nullopt;
    }
    return text[pos] - '0';
  };
  for (std::size_t pos = 0; pos < text.size(); ++pos) {
    if (text.compare(pos, 8, "freiburg") == 0) {
      if (auto n = numberAt(pos + 8)) return n;
    } else if (text.compare(pos, 2, "fr") == 0 &&
               (pos == 0 || !std::isalpha(static_cast<unsigned char>(text[pos - 1])))) {
      if (auto n = numberAt(pos + 2)) return n;
    }
  }
  return std::nullopt;
}

std::string commentLines(const std::filesystem::path& path, bool comments_only) {
  std::ifstream in(path);
  std::string text, line;
  for (int n = 0; n < 200 && std::getline(in, line); ++n) {
    if (!comments_only || (!line.empty() && line.front() == '#')) text += line + '\n';
  }
  return text;
}

std::optional<int> detectFreiburg(const std::filesystem::path& folder) {
  if (auto n = freiburgNumberIn(folderName(folder))) return n;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    std::string name = entry.path().filename().string();
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (entry.is_regular_file() && name.starts_with("readme")) {
      if (auto n = freiburgNumberIn(commentLines(entry.path(), false))) return n;
    }
  }
  for (const char* file : {"rgb.txt", "groundtruth.txt", "depth.txt"}) {
    if (auto n = freiburgNumberIn(commentLines(folder / file, true))) return n;
  }
  return std::nullopt;
}

struct StampedFile {
  double timestamp;
  std::filesystem::path file;
};

std::vector<StampedFile> readFileList(const std::filesystem::path& folder, const char* name) {
  const auto list = folder / name;
  std::vector<StampedFile> files;
  for (const TableRow& row : readTable(list, 2)) {
    files.push_back({parseNumber(row.fields[0], list, row.line), folder / row.fields[1]});
  }
  std::stable_sort(files.begin(), files.end(),
                   [](const auto& a, const auto& b) { return a.timestamp < b.timestamp; });
  return files;
}

const StampedFile* nearest(const std::vector<StampedFile>& sorted, double time) {
  const auto after =
      std::lower_bound(sorted.begin(), sorted.end(), time,
                       [](const StampedFile& f, double t) { return f.timestamp < t; });
  const StampedFile* best = nullptr;
  if (after != sorted.end()) best = &*after;
  if (after != sorted.begin()) {
    const StampedFile* before = &*std::prev(after);
    if (best == nullptr || time - before->timestamp < best->timestamp - time) best = before;
  }
  return best;
}

class TumReader : public TabulatedReader {
 public:
  TumReader(const std::filesystem::path& folder, const DatasetOptions& options) {
    info_.format = DatasetFormat::kTum;
    info_.path = folder;
    const std::vector<StampedFile> rgb = readFileList(folder, "rgb.txt");
    if (rgb.empty())
      throw DatasetError(fmt::format("{}: no frames", (folder / "rgb.txt").string()));
    std::vector<StampedFile> depth;
    if (std::filesystem::exists(folder / "depth.txt")) depth = readFileList(folder, "depth.txt");
    info_.has_depth = !depth.empty();

    for (const StampedFile& frame : rgb) {
      std::optional<std::filesystem::path> depth_file;
      if (info_.has_depth) {
        const StampedFile* match = nearest(depth, frame.timestamp);
        if (match == nullptr ||
            std::abs(match->timestamp - frame.timestamp) > kAssociationTolerance) {
          continue;
        }
        depth_file = match->file;
      }
      timestamps_.push_back(frame.timestamp);
      rgb_files_.push_back(frame.file);
      depth_files_.push_back(depth_file);
    }
    if (timestamps_.empty()) {
      throw DatasetError(fmt::format("{}: no rgb frame has a depth image within {} s",
                                     folder.string(), kAssociationTolerance));
    }

    if (std::filesystem::exists(folder / "groundtruth.txt")) {
      Trajectory trajectory = readTumTrajectory(folder / "groundtruth.txt");
      sortByTime(trajectory);
      for (double t : timestamps_) {
        ground_truth_.push_back(interpolatePose(trajectory, t, kDefaultPoseTimeTolerance));
      }
    }

    std::optional<CameraIntrinsics> native;
    if (std::filesystem::exists(folder / "camera.yaml")) {
      native = loadCameraFile(folder / "camera.yaml");
      if (native->depth_factor == 0.0) native->depth_factor = kDepthFactor;
    } else if (auto number = detectFreiburg(folder)) {
      native = freiburgCamera(*number);
    }
    const cv::Mat first = readImage(rgb_files_.front());
    camera_ = resolveCamera(
        native, options, first.size(), rgb_files_.front(),
        fmt::format(
            "{}: TUM folders carry no intrinsics and neither camera.yaml nor a freiburg1/2/3 "
            "hint (folder name, README, rgb.txt comments) was found: pass --camera "
            "FILE.yaml (see config/cameras/tum-fr*.yaml)",
            folder.string()));
    if (info_.has_depth && camera_.intrinsics().depth_factor == 0.0) {
      CameraIntrinsics with_depth = camera_.intrinsics();  // --camera without depth_factor
      with_depth.depth_factor = kDepthFactor;
      camera_ = PinholeCamera(with_depth);
    }
    finishTables();
  }

  DatasetFrame load(std::size_t index) override {
    DatasetFrame frame = beginFrame(index, std::string());
    const std::filesystem::path& rgb = rgb_files_[index];
    frame.name = rgb.filename().string();
    readFrameImage(rgb, content_.color, frame);
    checkImageSize(frame.gray, imageSize(camera_), rgb, "image");
    if (const auto& depth = depth_files_[index]; depth && content_.depth) {
      frame.depth = depthToMetres(readImage(*depth), camera_.intrinsics().depth_factor, *depth);
      checkImageSize(frame.depth, imageSize(camera_), *depth, "depth image");
    }
    return frame;
  }

 private:
  std::vector<std::filesystem::path> rgb_files_;
  std::vector<std::optional<std::filesystem::path>> depth_files_;
};

}  // namespace

std::unique_ptr<DatasetReader> openTumDataset(const std::filesystem::path& folder,
                                              const DatasetOptions& options) {
  return std::make_unique<TumReader>(folder, options);
}

}  // namespace edgeslam::detail
