#include "synth/ground_truth_masks.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "io/dataset_error.h"

namespace edgeslam {

std::optional<GroundTruthMasks> GroundTruthMasks::open(const std::filesystem::path& dataset_dir) {
  const auto list = dataset_dir / kListFile;
  if (!std::filesystem::is_regular_file(list)) return std::nullopt;
  std::ifstream in(list);
  if (!in) throw DatasetError(fmt::format("cannot open {}", list.string()));
  GroundTruthMasks masks;
  masks.list_ = list;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::string time_text, file;
    if (!(fields >> time_text >> file)) {
      throw DatasetError(
          fmt::format("{}:{}: expected 'timestamp file', found '{}'", list.string(), number, line));
    }
    double timestamp = 0.0;
    try {
      std::size_t used = 0;
      timestamp = std::stod(time_text, &used);
      if (used != time_text.size() || !std::isfinite(timestamp)) throw std::invalid_argument("");
    } catch (const std::exception&) {
      throw DatasetError(
          fmt::format("{}:{}: '{}' is not a timestamp", list.string(), number, time_text));
    }
    masks.timestamps_.push_back(timestamp);
    masks.files_.push_back(dataset_dir / file);
  }
  return masks;
}

cv::Mat1b GroundTruthMasks::load(std::size_t index) const {
  if (index >= files_.size()) {
    throw DatasetError(
        fmt::format("{}: no mask for frame {} ({} listed)", list_.string(), index, files_.size()));
  }
  const auto& file = files_[index];
  const cv::Mat mask = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (mask.empty()) throw DatasetError(fmt::format("cannot read mask {}", file.string()));
  if (mask.type() != CV_8UC1) {
    throw DatasetError(
        fmt::format("{}: a mask must be an 8-bit single-channel image", file.string()));
  }
  return mask;
}

std::optional<cv::Mat1b> GroundTruthMasks::loadAt(double timestamp, double tolerance_s) const {
  std::size_t best = files_.size();
  double best_gap = tolerance_s;
  for (std::size_t i = 0; i < timestamps_.size(); ++i) {
    const double gap = std::abs(timestamps_[i] - timestamp);
    if (gap <= best_gap) best = i, best_gap = gap;
  }
  if (best == files_.size()) return std::nullopt;
  return load(best);
}

std::optional<cv::Mat1b> loadGroundTruthMask(const std::filesystem::path& dataset_dir,
                                             std::size_t frame_index) {
  const auto masks = GroundTruthMasks::open(dataset_dir);
  if (!masks || frame_index >= masks->size()) return std::nullopt;
  return masks->load(frame_index);
}

}  // namespace edgeslam
