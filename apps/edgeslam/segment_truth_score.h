#pragma once
// `edgeslam segment --truth DIR`: the segmenter alone against the ground-truth masks of a
// generated dynamic sequence, to tell segmentation errors from mask-transfer errors in a run's
// transferred-mask IoU.
#include <filesystem>

#include "semantic/segmenter.h"

namespace edgeslam::cli {

struct TruthScoreOptions {
  int every = 1;   // score frames 0, every, 2*every, ...
  int reduce = 1;  // shrink each frame this many times first (keyframes reach the edge at 1/2)
};

// Prints one line per scored frame and a summary (IoU median and quartiles over frames where the
// truth or the prediction is non-empty, people missed, false alarms, time per frame). Throws
// std::invalid_argument when `dataset_dir` has no ground-truth masks.
void scoreSegmenterOnSequence(Segmenter& segmenter, const std::filesystem::path& dataset_dir,
                              const TruthScoreOptions& options);

}  // namespace edgeslam::cli
