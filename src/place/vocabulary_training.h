#pragma once
// Training a vocabulary: hierarchical k-medians of binary descriptors (k-means++ seeding, per-bit
// majority centres), then idf weights from the training images.
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <span>
#include <string_view>

#include "place/vocabulary.h"

namespace edgeslam {

struct VocabularyTrainingProgress {
  std::string_view stage;  // "clustering" or "weighting"
  std::size_t done = 0;    // clustering: descriptors x levels finished, of `total`
  std::size_t total = 0;
};

struct VocabularyTrainingOptions {
  int branching = 10;  // k
  int levels = 5;      // L
  WordWeighting weighting = WordWeighting::kTfIdf;
  int max_iterations = 10;  // assignment rounds per node (stops earlier once stable)
  int threads = 1;          // 0: every hardware thread
  std::uint64_t seed = 0;   // the result depends on the seed only, never on `threads`
  // Called one at a time (possibly from a worker thread) as work finishes.
  std::function<void(const VocabularyTrainingProgress&)> progress;

  // Throws std::invalid_argument naming the offending field.
  void validate() const;
};

// `image_descriptors`: one CV_8UC1 x 32 matrix per training image (images without features count
// as images for the idf). Throws std::invalid_argument when there is no descriptor at all or a
// matrix has the wrong type.
Vocabulary trainVocabulary(std::span<const cv::Mat> image_descriptors,
                           const VocabularyTrainingOptions& options = {});

}  // namespace edgeslam
