#pragma once
// A small vocabulary (k=10, L=4) for tests, trained in seconds on every `step`-th frame of shared
// sequences. Callers cache it (a function-local static) so a test process trains it once.
#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "features/orb_extractor.h"
#include "io/dataset.h"
#include "place/vocabulary_training.h"
#include "support/shared_data.h"

namespace edgeslam::test {

// `sequences`: shared dataset paths (relative to the shared folder) and their frame steps.
inline Vocabulary trainSmallVocabulary(
    const std::vector<std::pair<std::string, std::size_t>>& sequences, int num_features = 1000) {
  OrbExtractorOptions orb;
  orb.num_features = num_features;
  OrbExtractor extractor(orb);
  std::vector<cv::Mat> descriptors;
  for (const auto& [dataset, step] : sequences) {
    auto reader = openDataset(sharedPath(dataset));
    for (std::size_t i = 0; i < reader->info().frame_count; i += step) {
      descriptors.push_back(extractor.extract(reader->load(i).gray).descriptors);
    }
  }
  VocabularyTrainingOptions options;
  options.branching = 10;
  options.levels = 4;
  options.threads = 2;
  return trainVocabulary(descriptors, options);
}

// For runs of the binary, which need a vocabulary file (a fresh build has no default one): a small
// vocabulary trained on TUM fr2desk and KITTI 07 (other sequences than the tests run on), written
// as `folder`/small.vocab; returns its path.
inline std::string writeSmallVocabulary(const std::filesystem::path& folder) {
  std::filesystem::create_directories(folder);
  const auto path = folder / "small.vocab";
  trainSmallVocabulary({{"datasets/tum-fr2desk-20", 1}, {"datasets/kitti07-160", 8}}).save(path);
  return path.string();
}

}  // namespace edgeslam::test
