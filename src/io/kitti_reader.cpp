// KITTI odometry: image_0/ (left grey), optional image_1/ (right grey, rectified), times.txt,
// calib.txt (P0, P1), ground truth poses.txt in the folder or ../poses/<sequence>.txt.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <map>

#include "io/reader_support.h"
#include "io/readers.h"
#include "io/trajectory.h"

namespace edgeslam::detail {
namespace {

using ProjectionMatrix = std::array<double, 12>;

std::map<std::string, ProjectionMatrix> readCalibration(const std::filesystem::path& path) {
  std::map<std::string, ProjectionMatrix> matrices;
  for (const TableRow& row : readTable(path, 1)) {
    std::string name = row.fields[0];
    if (!name.ends_with(':')) continue;  // other lines (e.g. Tr:) are not needed
    name.pop_back();
    if (!name.starts_with('P')) continue;
    if (row.fields.size() != 13) {
      throw DatasetError(fmt::format("{}:{}: {} needs 12 numbers, found {}", path.string(),
                                     row.line, name, row.fields.size() - 1));
    }
    ProjectionMatrix p{};
    for (std::size_t i = 0; i < 12; ++i) p[i] = parseNumber(row.fields[i + 1], path, row.line);
    matrices[name] = p;
  }
  return matrices;
}

std::optional<std::filesystem::path> findGroundTruth(const std::filesystem::path& folder) {
  if (std::filesystem::exists(folder / "poses.txt")) return folder / "poses.txt";
  const std::string sequence = folderName(folder);
  if (!sequence.empty() && std::all_of(sequence.begin(), sequence.end(),
                                       [](unsigned char c) { return std::isdigit(c) != 0; })) {
    // Official layout: dataset/sequences/07/ and dataset/poses/07.txt.
    const auto official =
        std::filesystem::absolute(folder).lexically_normal().parent_path().parent_path() / "poses" /
        (sequence + ".txt");
    const auto beside = std::filesystem::absolute(folder).lexically_normal().parent_path() /
                        "poses" / (sequence + ".txt");
    if (std::filesystem::exists(beside)) return beside;
    if (std::filesystem::exists(official)) return official;
  }
  return std::nullopt;
}

// Frame number of a KITTI image (000123.png -> 123), or nullopt for other names.
std::optional<std::size_t> frameNumber(const std::filesystem::path& image) {
  const std::string stem = image.stem().string();
  if (stem.empty() || stem.size() > 9 ||
      !std::all_of(stem.begin(), stem.end(), [](unsigned char c) { return std::isdigit(c); })) {
    return std::nullopt;
  }
  return static_cast<std::size_t>(std::stoul(stem));
}

class KittiReader : public TabulatedReader {
 public:
  KittiReader(const std::filesystem::path& folder, const DatasetOptions& options) {
    info_.format = DatasetFormat::kKitti;
    info_.path = folder;
    if (!std::filesystem::is_directory(folder / "image_0")) {
      throw DatasetError(fmt::format("{}: KITTI folder without image_0/", folder.string()));
    }
    // times.txt and poses may cover the whole sequence while the images are an excerpt of it:
    // image NNNNNN.png takes line NNNNNN of each (its position when the name is not a number).
    const std::vector<double> times = readTimes(folder / "times.txt");
    left_ = listImages(folder / "image_0");
    if (left_.empty()) {
      throw DatasetError(fmt::format("{}: no images", (folder / "image_0").string()));
    }
    for (std::size_t i = 0; i < left_.size(); ++i) {
      const std::size_t line = frameNumber(left_[i]).value_or(i);
      if (line >= times.size()) {
        throw DatasetError(fmt::format("{}: no timestamp for {} ({} has {} lines)", folder.string(),
                                       left_[i].filename().string(),
                                       (folder / "times.txt").string(), times.size()));
      }
      lines_.push_back(line);
      timestamps_.push_back(times[line]);
    }
    if (std::filesystem::is_directory(folder / "image_1")) {
      for (const auto& left : left_) {
        right_.push_back(folder / "image_1" / left.filename());
        if (!std::filesystem::exists(right_.back())) {
          throw DatasetError(fmt::format("{}: image_1/ exists but has no {}", folder.string(),
                                         left.filename().string()));
        }
      }
      info_.has_stereo = true;
      info_.stereo_rectified = true;
    }

    if (const auto poses_file = findGroundTruth(folder)) {
      const std::vector<SE3d> poses = readKittiPoses(*poses_file);
      for (std::size_t i = 0; i < left_.size(); ++i) {
        if (lines_[i] >= poses.size()) {
          throw DatasetError(fmt::format("{} has {} poses, none for {}", poses_file->string(),
                                         poses.size(), left_[i].filename().string()));
        }
        ground_truth_.push_back(poses[lines_[i]]);
      }
    }

    const cv::Mat first = readImage(left_.front());
    std::optional<CameraIntrinsics> native;
    const auto calib_file = folder / "calib.txt";
    if (std::filesystem::exists(calib_file))
      native = cameraFromCalibration(calib_file, first.size());
    camera_ =
        resolveCamera(native, options, first.size(), left_.front(),
                      fmt::format("{}: no calib.txt; pass --camera FILE.yaml", folder.string()));
    finishTables();
  }

  DatasetFrame load(std::size_t index) override {
    DatasetFrame frame = beginFrame(index, std::string());
    frame.name = left_[index].filename().string();
    readFrameImage(left_[index], content_.color, frame);
    checkImageSize(frame.gray, imageSize(camera_), left_[index], "image");
    if (!right_.empty() && content_.right) {
      DatasetFrame right;
      setImages(readImage(right_[index]), right_[index], right);
      checkImageSize(right.gray, imageSize(camera_), right_[index], "right image");
      frame.right_gray = right.gray;
    }
    return frame;
  }

 private:
  CameraIntrinsics cameraFromCalibration(const std::filesystem::path& calib_file,
                                         cv::Size image_size) const {
    const auto matrices = readCalibration(calib_file);
    const auto p0 = matrices.find("P0");
    if (p0 == matrices.end())
      throw DatasetError(fmt::format("{}: no P0 line", calib_file.string()));
    const ProjectionMatrix& p = p0->second;
    CameraIntrinsics in;
    in.width = image_size.width;
    in.height = image_size.height;
    in.fx = p[0], in.fy = p[5], in.cx = p[2], in.cy = p[6];
    in.fps = fpsFromTimestamps(timestamps_);
    // The baseline is known from P1 even when only the left images are present.
    if (const auto p1 = matrices.find("P1"); p1 != matrices.end()) {
      if (!(p1->second[0] > 0.0)) {
        throw DatasetError(fmt::format("{}: P1 has no focal length", calib_file.string()));
      }
      in.baseline_m = -p1->second[3] / p1->second[0];
    } else if (info_.has_stereo) {
      throw DatasetError(
          fmt::format("{}: image_1/ exists but there is no P1 line", calib_file.string()));
    }
    return in;
  }

  std::vector<std::filesystem::path> left_;
  std::vector<std::filesystem::path> right_;
  std::vector<std::size_t> lines_;  // line of times.txt / poses of each frame
};

}  // namespace

std::unique_ptr<DatasetReader> openKittiDataset(const std::filesystem::path& folder,
                                                const DatasetOptions& options) {
  return std::make_unique<KittiReader>(folder, options);
}

}  // namespace edgeslam::detail
