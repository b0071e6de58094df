#include "synth/tum_sequence_writer.h"

#include <fmt/format.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "io/camera_file.h"
#include "io/dataset_error.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;

void writeImage(const fs::path& path, const cv::Mat& image) {
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& e) {
    throw DatasetError(fmt::format("cannot write {}: {}", path.string(), e.what()));
  }
  if (!written) throw DatasetError(fmt::format("cannot write {}", path.string()));
}

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  if (!out) throw DatasetError(fmt::format("cannot write {}", path.string()));
}

cv::Mat depthImage(const cv::Mat& depth_m, double depth_factor) {
  cv::Mat1w raw(depth_m.size());
  for (int y = 0; y < depth_m.rows; ++y) {
    const float* in = depth_m.ptr<float>(y);
    for (int x = 0; x < depth_m.cols; ++x) {
      const double units = std::isfinite(in[x]) && in[x] > 0.0f ? in[x] * depth_factor : 0.0;
      raw(y, x) = cv::saturate_cast<std::uint16_t>(std::lround(std::min(units, 65535.0)));
    }
  }
  return raw;
}

}  // namespace

TumSequenceWriter::TumSequenceWriter(fs::path folder, std::string header, double depth_factor)
    : folder_(std::move(folder)), header_(std::move(header)), depth_factor_(depth_factor) {
  for (const char* sub : {"rgb", "depth", "masks"}) {
    if (std::string(sub) == "depth" && depth_factor_ <= 0.0) continue;
    fs::create_directories(folder_ / sub);
  }
}

void TumSequenceWriter::addFrame(double timestamp, const cv::Mat& image, const cv::Mat& depth_m,
                                 const cv::Mat1b& mask,
                                 const std::optional<SE3d>& camera_to_world) {
  const std::string name = fmt::format("{:06d}.png", frames_);
  const std::string stamp = fmt::format("{:.6f}", timestamp);
  writeImage(folder_ / "rgb" / name, image);
  rgb_list_ += fmt::format("{} rgb/{}\n", stamp, name);
  if (depth_factor_ > 0.0) {
    if (depth_m.empty()) {
      throw DatasetError(fmt::format("frame {}: the sequence has depth but this frame none", name));
    }
    writeImage(folder_ / "depth" / name, depthImage(depth_m, depth_factor_));
    depth_list_ += fmt::format("{} depth/{}\n", stamp, name);
  }
  writeImage(folder_ / "masks" / name, mask);
  mask_list_ += fmt::format("{} masks/{}\n", stamp, name);
  // The same printed timestamp as the lists, so the reader pairs them exactly.
  if (camera_to_world) ground_truth_.push_back({std::stod(stamp), *camera_to_world});
  ++frames_;
}

void TumSequenceWriter::finish(const CameraIntrinsics& camera) {
  const std::string comment = "# " + header_ + "\n";
  writeText(folder_ / "rgb.txt", comment + "# timestamp filename\n" + rgb_list_);
  if (depth_factor_ > 0.0) {
    writeText(folder_ / "depth.txt", comment + "# timestamp filename\n" + depth_list_);
  }
  writeText(folder_ / "masks.txt",
            comment + "# timestamp filename (255 = pasted person, alpha > 0.5)\n" + mask_list_);
  writeTumTrajectory(folder_ / "groundtruth.txt", ground_truth_);
  CameraIntrinsics written = camera;
  written.baseline_m = 0.0;  // no right images are written
  written.depth_factor = depth_factor_ > 0.0 ? depth_factor_ : 0.0;
  saveCameraFile(folder_ / "camera.yaml", written);
}

}  // namespace edgeslam
