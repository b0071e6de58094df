#include "io/preloaded_dataset.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace edgeslam {
namespace {

std::size_t matBytes(const cv::Mat& mat) {
  return mat.empty() ? 0 : mat.total() * mat.elemSize();
}

// MemAvailable of /proc/meminfo in bytes; nullopt where it cannot be read.
std::optional<std::size_t> availableMemoryBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::size_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024;
  }
  return std::nullopt;
}

DatasetFrame copyOf(const DatasetFrame& frame) {
  DatasetFrame copy = frame;
  copy.gray = frame.gray.clone();
  copy.color = frame.color.clone();
  copy.depth = frame.depth.clone();
  copy.right_gray = frame.right_gray.clone();
  return copy;
}

class PreloadedReader : public DatasetReader {
 public:
  PreloadedReader(std::unique_ptr<DatasetReader> inner, std::vector<DatasetFrame> frames)
      : inner_(std::move(inner)), frames_(std::move(frames)), info_(inner_->info()) {
    info_.frame_count = frames_.size();
    timestamps_.assign(inner_->timestamps().begin(),
                       inner_->timestamps().begin() + static_cast<std::ptrdiff_t>(frames_.size()));
    ground_truth_.assign(
        inner_->groundTruth().begin(),
        inner_->groundTruth().begin() + static_cast<std::ptrdiff_t>(frames_.size()));
  }

  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return inner_->camera(); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return ground_truth_; }

  DatasetFrame load(std::size_t index) override {
    if (index >= frames_.size()) {
      throw std::out_of_range(fmt::format("frame {} of {} preloaded", index, frames_.size()));
    }
    return copyOf(frames_[index]);
  }

 private:
  std::unique_ptr<DatasetReader> inner_;
  std::vector<DatasetFrame> frames_;
  DatasetInfo info_;
  std::vector<double> timestamps_;
  std::vector<std::optional<SE3d>> ground_truth_;
};

}  // namespace

std::size_t frameBytes(const DatasetFrame& frame) {
  return matBytes(frame.gray) + matBytes(frame.color) + matBytes(frame.depth) +
         matBytes(frame.right_gray);
}

std::unique_ptr<DatasetReader> preloadFrames(std::unique_ptr<DatasetReader> reader,
                                             std::size_t count,
                                             const std::function<void(std::size_t)>& progress) {
  count = std::min(count, reader->info().frame_count);
  std::vector<DatasetFrame> frames;
  frames.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    frames.push_back(reader->load(i));
    if (i == 0) {
      const std::size_t total = frameBytes(frames.front()) * count;
      const std::optional<std::size_t> available = availableMemoryBytes();
      if (available && total > *available / 2) {
        throw std::runtime_error(fmt::format(
            "--preload: {} frames of {} would take {:.1f} GB, more than half of the {:.1f} GB "
            "available; play fewer frames (--max-frames, --frames) or leave --preload off",
            count, reader->info().path.string(), static_cast<double>(total) / 1e9,
            static_cast<double>(*available) / 1e9));
      }
    }
    if (progress) progress(i + 1);
  }
  return std::make_unique<PreloadedReader>(std::move(reader), std::move(frames));
}

}  // namespace edgeslam
