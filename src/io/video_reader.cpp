// A video file OpenCV's videoio can decode. Frame i is at i / fps (the container's rate, else
// the camera file's, else 30). The camera comes from `<name>.yaml` or `<name>.<ext>.yaml` beside
// the video, or --camera. Frames decode sequentially; going back re-opens the file and skips.
// The frame count is the container's when it reports one (else counted by grabbing every frame),
// so a container that over-reports makes load() fail at the true end with a clear error.
#include <fmt/format.h>

#include <opencv2/videoio.hpp>
#include <opencv2/videoio/registry.hpp>

#include "io/camera_file.h"
#include "io/reader_support.h"
#include "io/readers.h"

namespace edgeslam::detail {
namespace {

constexpr double kDefaultFps = 30.0;

std::optional<std::filesystem::path> findCameraFile(const std::filesystem::path& video) {
  auto replaced = video;
  replaced.replace_extension(".yaml");
  if (std::filesystem::exists(replaced)) return replaced;
  auto appended = video;
  appended += ".yaml";
  if (std::filesystem::exists(appended)) return appended;
  return std::nullopt;
}

class VideoReader : public TabulatedReader {
 public:
  VideoReader(const std::filesystem::path& file, const DatasetOptions& options) : file_(file) {
    info_.format = DatasetFormat::kVideo;
    info_.path = file;
    open();
    cv::Mat first;
    if (!capture_.read(first) || first.empty()) {
      throw DatasetError(fmt::format("{}: cannot decode the first frame", file.string()));
    }
    std::optional<CameraIntrinsics> native;
    const auto camera_file = findCameraFile(file);
    if (camera_file) native = loadCameraFile(*camera_file);
    camera_ = resolveCamera(
        native, options, first.size(), file,
        fmt::format("{}: a video needs a camera: put {} beside it or pass --camera FILE.yaml",
                    file.string(),
                    std::filesystem::path(file).replace_extension(".yaml").filename().string()));

    double fps = capture_.get(cv::CAP_PROP_FPS);
    if (!(fps > 0.0 && fps < 1000.0)) {
      fps = camera_.intrinsics().fps > 0.0 ? camera_.intrinsics().fps : kDefaultFps;
    }
    info_.fps = fps;
    const double reported = capture_.get(cv::CAP_PROP_FRAME_COUNT);
    const std::size_t count = reported >= 1.0 ? static_cast<std::size_t>(reported) : countFrames();
    for (std::size_t i = 0; i < count; ++i) timestamps_.push_back(static_cast<double>(i) / fps);
    pending_first_ = std::move(first);
    next_index_ = 1;
    finishTables();
  }

  DatasetFrame load(std::size_t index) override {
    DatasetFrame frame = beginFrame(index, fmt::format("{}#{}", file_.filename().string(), index));
    cv::Mat image;
    if (index == 0 && !pending_first_.empty()) {
      image = std::move(pending_first_);
      pending_first_.release();
    } else {
      if (index < next_index_) {
        open();
        next_index_ = 0;
      }
      pending_first_.release();
      while (next_index_ < index) {
        if (!capture_.grab()) throwEnded();
        ++next_index_;
      }
      if (!capture_.read(image) || image.empty()) throwEnded();
      ++next_index_;
    }
    setImages(image, file_, frame);
    checkImageSize(frame.gray, imageSize(camera_), file_, "frame");
    return frame;
  }

 private:
  // Only file backends are tried: CAP_ANY also probes camera backends (libdc1394 via libusb),
  // which is slow and leaks when the file is not a video.
  void open() {
    capture_.release();
    for (const auto backend : {cv::CAP_FFMPEG, cv::CAP_GSTREAMER, cv::CAP_OPENCV_MJPEG}) {
      if (!cv::videoio_registry::hasBackend(backend)) continue;
      try {
        if (capture_.open(file_.string(), backend) && capture_.isOpened()) return;
      } catch (const cv::Exception&) {
      }
      capture_.release();
    }
    throw DatasetError(
        fmt::format("cannot open video {} (not a video, or no codec for it in this OpenCV build)",
                    file_.string()));
  }

  std::size_t countFrames() {
    std::size_t count = 1;  // the first frame was read already
    while (capture_.grab()) ++count;
    open();
    cv::Mat skip;
    capture_.read(skip);
    return count;
  }

  [[noreturn]] void throwEnded() const {
    throw DatasetError(fmt::format("{}: video ended after {} frames though it reported {}",
                                   file_.string(), next_index_, timestamps_.size()));
  }

  std::filesystem::path file_;
  cv::VideoCapture capture_;
  cv::Mat pending_first_;
  std::size_t next_index_ = 0;
};

}  // namespace

std::unique_ptr<DatasetReader> openVideoDataset(const std::filesystem::path& file,
                                                const DatasetOptions& options) {
  return std::make_unique<VideoReader>(file, options);
}

}  // namespace edgeslam::detail
