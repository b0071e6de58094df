#include "io/repeated_dataset.h"

#include <fmt/format.h>

#include <stdexcept>
#include <utility>
#include <vector>

namespace edgeslam {
namespace {

// One frame interval past the last frame: the mean interval, else the dataset's rate, else 1/30 s.
double passPeriod(const std::vector<double>& stamps, double fps) {
  if (stamps.empty()) return 0.0;
  double interval = fps > 0.0 ? 1.0 / fps : 1.0 / 30.0;
  if (stamps.size() >= 2) {
    interval = (stamps.back() - stamps.front()) / static_cast<double>(stamps.size() - 1);
  }
  return stamps.back() - stamps.front() + interval;
}

class RepeatedReader : public DatasetReader {
 public:
  RepeatedReader(std::unique_ptr<DatasetReader> inner, std::size_t passes)
      : inner_(std::move(inner)), count_(inner_->info().frame_count), info_(inner_->info()) {
    info_.frame_count = count_ * passes;
    const std::vector<double>& stamps = inner_->timestamps();
    const double period = passPeriod(stamps, info_.fps);
    timestamps_.reserve(info_.frame_count);
    ground_truth_.reserve(info_.frame_count);
    for (std::size_t pass = 0; pass < passes; ++pass) {
      for (double t : stamps) timestamps_.push_back(t + static_cast<double>(pass) * period);
      ground_truth_.insert(ground_truth_.end(), inner_->groundTruth().begin(),
                           inner_->groundTruth().end());
    }
  }

  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return inner_->camera(); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return ground_truth_; }

  DatasetFrame load(std::size_t index) override {
    if (index >= info_.frame_count) {
      throw std::out_of_range(
          fmt::format("frame {} of {} frames played repeatedly", index, info_.frame_count));
    }
    inner_->setContent(content());
    DatasetFrame frame = inner_->load(index % count_);
    frame.index = index;
    frame.timestamp = timestamps_[index];
    return frame;
  }

 private:
  std::unique_ptr<DatasetReader> inner_;
  std::size_t count_;
  DatasetInfo info_;
  std::vector<double> timestamps_;
  std::vector<std::optional<SE3d>> ground_truth_;
};

}  // namespace

std::unique_ptr<DatasetReader> repeatFrames(std::unique_ptr<DatasetReader> reader,
                                            std::size_t passes) {
  if (passes == 0) throw std::invalid_argument("a sequence is played at least once");
  if (passes == 1 || reader->info().frame_count == 0) return reader;
  return std::make_unique<RepeatedReader>(std::move(reader), passes);
}

}  // namespace edgeslam
