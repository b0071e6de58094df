#include "io/repeated_dataset.h"

#include <fmt/format.h>

#include <stdexcept>
#include <utility>
#include <vector>

#include "io/reindexed_reader.h"

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

}  // namespace

std::unique_ptr<DatasetReader> repeatFrames(std::unique_ptr<DatasetReader> reader,
                                            std::size_t passes) {
  if (passes == 0) throw std::invalid_argument("a sequence is played at least once");
  if (passes == 1 || reader->info().frame_count == 0) return reader;
  const std::size_t count = reader->info().frame_count;
  const std::vector<double>& stamps = reader->timestamps();
  const double period = passPeriod(stamps, reader->info().fps);
  std::vector<std::size_t> inner_index;
  std::vector<double> timestamps;
  inner_index.reserve(count * passes);
  timestamps.reserve(count * passes);
  for (std::size_t pass = 0; pass < passes; ++pass) {
    for (std::size_t i = 0; i < count; ++i) {
      inner_index.push_back(i);
      timestamps.push_back(stamps[i] + static_cast<double>(pass) * period);
    }
  }
  return std::make_unique<ReindexedReader>(std::move(reader), std::move(inner_index),
                                           std::move(timestamps),
                                           fmt::format("{} frames played {} times", count, passes));
}

}  // namespace edgeslam
