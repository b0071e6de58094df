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

std::vector<FrameRange> parseFrameRanges(const std::string& text) {
  std::vector<FrameRange> ranges;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string part =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    try {
      ranges.push_back(parseFrameRange(part));
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument(fmt::format(
          "bad frame ranges '{}': expected A-B or several, comma-separated (0-200,375-999)", text));
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return ranges;
}

std::unique_ptr<DatasetReader> selectFrames(std::unique_ptr<DatasetReader> reader,
                                            const std::vector<FrameRange>& ranges) {
  if (ranges.empty()) throw std::invalid_argument("no frame range to play");
  if (ranges.size() == 1) return selectFrames(std::move(reader), ranges.front());
  const std::size_t frame_count = reader->info().frame_count;
  const std::vector<double>& stamps = reader->timestamps();
  double interval = reader->info().fps > 0.0 ? 1.0 / reader->info().fps : 1.0 / 30.0;
  if (stamps.size() >= 2) {
    interval = (stamps.back() - stamps.front()) / static_cast<double>(stamps.size() - 1);
  }
  std::vector<std::size_t> inner_index;
  std::vector<double> timestamps;
  for (const FrameRange& range : ranges) {
    checkFrameRange(range, frame_count);
    // The first range keeps its times; a next one starts one interval after the previous end.
    const double shift =
        timestamps.empty() ? 0.0 : timestamps.back() + interval - stamps[range.first];
    for (std::size_t k = range.first; k <= range.last; ++k) {
      inner_index.push_back(k);
      timestamps.push_back(stamps[k] + shift);
    }
  }
  const std::size_t total = inner_index.size();
  return std::make_unique<ReindexedReader>(
      std::move(reader), std::move(inner_index), std::move(timestamps),
      fmt::format("{} frames in {} ranges", total, ranges.size()));
}

}  // namespace edgeslam
