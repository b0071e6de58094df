#include "io/frame_range.h"

#include <fmt/format.h>

#include <cctype>
#include <stdexcept>
#include <utility>
#include <vector>

#include "io/reindexed_reader.h"

namespace edgeslam {
namespace {

bool allDigits(const std::string& text) {
  if (text.empty() || text.size() > 12) return false;
  for (char c : text) {
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

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
  std::vector<std::size_t> inner_index(range.count());
  std::vector<double> timestamps(range.count());
  for (std::size_t i = 0; i < range.count(); ++i) {
    inner_index[i] = range.first + i;
    timestamps[i] = reader->timestamps()[range.first + i];
  }
  return std::make_unique<ReindexedReader>(std::move(reader), std::move(inner_index),
                                           std::move(timestamps),
                                           fmt::format("a {}-frame range", range.count()));
}

}  // namespace edgeslam
