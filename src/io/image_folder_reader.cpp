// A folder of images (png/jpg/jpeg/bmp/ppm/pgm, natural order) with camera.yaml (or --camera),
// optional times.txt (one timestamp per image) and optional groundtruth.txt (TUM format).
// Without times.txt frame i is at i / fps, fps from the camera file or 30.
#include <fmt/format.h>

#include "io/camera_file.h"
#include "io/pose_interpolation.h"
#include "io/reader_support.h"
#include "io/readers.h"

namespace edgeslam::detail {
namespace {

constexpr double kDefaultFps = 30.0;

class ImageFolderReader : public TabulatedReader {
 public:
  ImageFolderReader(const std::filesystem::path& folder, const DatasetOptions& options) {
    info_.format = DatasetFormat::kImages;
    info_.path = folder;
    if (!std::filesystem::is_directory(folder)) {
      throw DatasetError(fmt::format("not a folder: {}", folder.string()));
    }
    images_ = listImages(folder);
    if (images_.empty()) {
      throw DatasetError(
          fmt::format("{}: no image files (png, jpg, jpeg, bmp, ppm, pgm)", folder.string()));
    }
    std::optional<CameraIntrinsics> native;
    if (std::filesystem::exists(folder / "camera.yaml")) {
      native = loadCameraFile(folder / "camera.yaml");
    }
    const cv::Mat first = readImage(images_.front());
    camera_ = resolveCamera(
        native, options, first.size(), images_.front(),
        fmt::format("{}: an image folder needs a camera: put camera.yaml in it or pass --camera "
                    "FILE.yaml",
                    folder.string()));

    const double fps = camera_.intrinsics().fps > 0.0 ? camera_.intrinsics().fps : kDefaultFps;
    if (std::filesystem::exists(folder / "times.txt")) {
      timestamps_ = readTimes(folder / "times.txt");
      if (timestamps_.size() != images_.size()) {
        throw DatasetError(fmt::format("{} has {} timestamps but the folder has {} images",
                                       (folder / "times.txt").string(), timestamps_.size(),
                                       images_.size()));
      }
    } else {
      for (std::size_t i = 0; i < images_.size(); ++i) {
        timestamps_.push_back(static_cast<double>(i) / fps);
      }
      info_.fps = fps;
    }
    if (std::filesystem::exists(folder / "groundtruth.txt")) {
      Trajectory trajectory = readTumTrajectory(folder / "groundtruth.txt");
      sortByTime(trajectory);
      for (double t : timestamps_) {
        ground_truth_.push_back(interpolatePose(trajectory, t, kDefaultPoseTimeTolerance));
      }
    }
    finishTables();
  }

  DatasetFrame load(std::size_t index) override {
    DatasetFrame frame = beginFrame(index, std::string());
    const std::filesystem::path& image = images_[index];
    frame.name = image.filename().string();
    readFrameImage(image, content_.color, frame);
    checkImageSize(frame.gray, imageSize(camera_), image, "image");
    return frame;
  }

 private:
  std::vector<std::filesystem::path> images_;
};

}  // namespace

std::unique_ptr<DatasetReader> openImageFolderDataset(const std::filesystem::path& folder,
                                                      const DatasetOptions& options) {
  return std::make_unique<ImageFolderReader>(folder, options);
}

}  // namespace edgeslam::detail
