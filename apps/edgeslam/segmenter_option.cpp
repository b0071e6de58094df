#include "segmenter_option.h"

#include <stdexcept>
#include <string>

namespace edgeslam::cli {

SegmenterOptions segmenterOptions(const std::filesystem::path& models_dir, int detector_input) {
  SegmenterOptions options;
  if (!models_dir.empty()) options.model_dir = models_dir;
  // Keyframes are segmented at half resolution. The input size trades recall for latency, and a
  // late mask costs more than a missed limb: on a generated 7-Scenes sequence (RGB-D, local mode)
  // transferred-mask IoU was 0.70 at 256, 0.32 at 320, 0.30 at 384 and 0.18 at 512 (~55, 80,
  // 120 and 330 ms per keyframe on one core here).
  options.detector_input_size = detector_input;
  return options;
}

std::shared_ptr<Segmenter> loadSegmenter(const SegmenterOptions& options) {
  try {
    return makeSegmenter(options);
  } catch (const std::runtime_error& e) {
    // A missing or unreadable model (bad options are std::invalid_argument and say so themselves).
    throw std::runtime_error(std::string(e.what()) +
                             " (semantic culling needs the segmentation models: pass --models DIR "
                             "or set EDGESLAM_SHARED; or run with --semantic off)");
  }
}

}  // namespace edgeslam::cli
