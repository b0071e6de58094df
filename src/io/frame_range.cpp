#include "io/frame_range.h"

#include <fmt/format.h>

#include <cctype>
#include <stdexcept>
#include <utility>
#include <vector>

namespace edgeslam {
namespace {

bool allDigits(const std::string& text) {
  if (text.empty() || text.size() > 12) return false;
  for (char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

class FrameRangeReader : public DatasetReader {
 public:
  FrameRangeReader(std::unique_ptr<DatasetReader> inner, const FrameRange& range)
      : inner_(std::move(inner)), first_(range.first), info_(inner_->info()) {
    info_.frame_count = range.count();
    const auto begin = static_cast<std::ptrdiff_t>(range.first);
    const auto end = static_cast<std::ptrdiff_t>(range.last + 1);
    timestamps_.assign(inner_->timestamps().begin() + begin, inner_->timestamps().begin() + end);
    ground_truth_.assign(inner_->groundTruth().begin() + begin,
                         inner_->groundTruth().begin() + end);
    info_.has_ground_truth = false;
    for (const auto& pose : ground_truth_) info_.has_ground_truth |= pose.has_value();
  }

  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return inner_->camera(); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return ground_truth_; }

  DatasetFrame load(std::size_t index) override {
    if (index >= info_.frame_count) {
      throw std::out_of_range(
          fmt::format("frame {} of a {}-frame range", index, info_.frame_count));
    }
    inner_->setContent(content());
    DatasetFrame frame = inner_->load(first_ + index);
    frame.index = index;
    return frame;
  }

 private:
  std::unique_ptr<DatasetReader> inner_;
  std::size_t first_;
  DatasetInfo info_;
  std::vector<double> timestamps_;
  std::vector<std::optional<SE3d>> ground_truth_;
};

}  // namespace

FrameRange parseFrameRange(const std::string& text) {
  const auto dash = text.find('-');
  const std::string first = dash == std::string::npos ? std::string() : text.substr(0, dash);
  const std::string last = dash == std::string::npos ? std::string() : text.substr(dash + 1);
  if (!allDigits(first) || !allDigits(last)) {
    throw std::invalid_argument(fmt::format(
        "bad frame range '{}': expected A-B with frame indices A <= B, e.g. 0-299", text));
  }
  FrameRange range{std::stoul(first), std::stoul(last)};
  if (range.first > range.last) {
    throw std::invalid_argument(
        fmt::format("bad frame range '{}': the first frame is after the last", text));
  }
  return range;
}

void checkFrameRange(const FrameRange& range, std::size_t frame_count) {
  if (range.first > range.last || range.last >= frame_count) {
    throw std::invalid_argument(
        fmt::format("frame range {}-{} is outside the dataset's {} frames (0-{})", range.first,
                    range.last, frame_count, frame_count == 0 ? 0 : frame_count - 1));
  }
}

std::unique_ptr<DatasetReader> selectFrames(std::unique_ptr<DatasetReader> reader,
                                            const FrameRange& range) {
  checkFrameRange(range, reader->info().frame_count);
  if (range.first == 0 && range.count() == reader->info().frame_count) return reader;
  return std::make_unique<FrameRangeReader>(std::move(reader), range);
}

}  // namespace edgeslam
