#pragma once
// A dataset seen through a list of its frames: frame i of the view is frame `inner_index[i]` of
// the reader underneath, at `timestamps[i]`. `--frames A-B` (a stretch) and `--repeat N` (the
// sequence again and again, time going on) are both such views.
#include <fmt/format.h>

#include <cstddef>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "io/dataset.h"

namespace edgeslam {

class ReindexedReader : public DatasetReader {
 public:
  // `what` names the view in errors ("a 300-frame range"). Sizes must match; indices must be
  // frames of `inner`.
  ReindexedReader(std::unique_ptr<DatasetReader> inner, std::vector<std::size_t> inner_index,
                  std::vector<double> timestamps, std::string what)
      : inner_(std::move(inner)),
        inner_index_(std::move(inner_index)),
        timestamps_(std::move(timestamps)),
        what_(std::move(what)),
        info_(inner_->info()) {
    info_.frame_count = inner_index_.size();
    ground_truth_.reserve(inner_index_.size());
    info_.has_ground_truth = false;
    for (const std::size_t k : inner_index_) {
      ground_truth_.push_back(inner_->groundTruth().at(k));
      info_.has_ground_truth |= ground_truth_.back().has_value();
    }
  }

  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return inner_->camera(); }
  const std::vector<double>& timestamps() const override { return timestamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return ground_truth_; }

  DatasetFrame load(std::size_t index) override {
    if (index >= info_.frame_count) {
      throw std::out_of_range(fmt::format("frame {} of {}", index, what_));
    }
    inner_->setContent(content());
    DatasetFrame frame = inner_->load(inner_index_[index]);
    frame.index = index;
    frame.timestamp = timestamps_[index];
    return frame;
  }

 private:
  std::unique_ptr<DatasetReader> inner_;
  std::vector<std::size_t> inner_index_;
  std::vector<double> timestamps_;
  std::string what_;
  DatasetInfo info_;
  std::vector<std::optional<SE3d>> ground_truth_;
};

}  // namespace edgeslam
