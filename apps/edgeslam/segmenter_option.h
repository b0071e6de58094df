#pragma once
// The segmentation models behind `--semantic on`: where they are (`--models DIR`, else the shared
// models folder) and a clear error when they are missing, before any frame is processed.
#include <filesystem>
#include <memory>

#include "semantic/segmenter.h"

namespace edgeslam::cli {

// Options for the default backend with `models_dir` (empty: defaultModelDirectory()).
SegmenterOptions segmenterOptions(const std::filesystem::path& models_dir,
                                  int detector_input = 256);

// Loads the models once; throws std::runtime_error naming the file and how to fix it, or
// std::invalid_argument for bad options (e.g. a detector input that is not a multiple of 32).
std::shared_ptr<Segmenter> loadSegmenter(const SegmenterOptions& options);

}  // namespace edgeslam::cli
