#pragma once
// `edgeslam synth-dynamic`: a dynamic benchmark sequence made from a real static one by pasting
// real people (cut out of photos) that walk over the frames; written in the TUM RGB-D layout with
// per-frame ground-truth people masks and a synth.json description.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "io/dataset.h"
#include "io/frame_range.h"
#include "synth/people_compositor.h"
#include "synth/people_motion.h"
#include "synth/person_sprite.h"

namespace edgeslam {

struct DynamicSequenceOptions {
  std::filesystem::path dataset;
  DatasetFormat format = DatasetFormat::kAuto;
  std::filesystem::path out;
  std::uint64_t seed = 1;
  std::optional<FrameRange> frames;  // all frames when absent
  int people_count = 0;              // 0: 1-3, drawn from the seed
  // Body sizes are tuned so that the median share of the image covered by people, over the frames
  // that show someone, is close to this.
  double target_coverage = 0.22;
  // Allows an existing non-empty `out`; the files this generator writes are replaced.
  bool overwrite = false;
  std::string people_dir;  // recorded in synth.json only
  CompositeOptions composite;
  std::function<void(std::size_t done, std::size_t total)> progress;
};

struct CoverageStats {
  std::size_t frames_with_people = 0;
  double median = 0.0, mean = 0.0, min = 0.0, max = 0.0, p10 = 0.0, p90 = 0.0;
};

// Statistics over the frames with a non-zero coverage.
CoverageStats coverageStats(const std::vector<double>& per_frame);

struct DynamicSequenceSummary {
  std::filesystem::path out;
  std::size_t frames = 0;
  bool has_depth = false;
  std::size_t people = 0;
  double base_height_px = 0.0;
  CoverageStats coverage;
  std::vector<double> coverage_per_frame;
  double elapsed_s = 0.0;
};

// Throws DatasetError (source unreadable), std::invalid_argument (bad range, out == dataset) or
// std::runtime_error (out not empty without overwrite) before writing anything.
DynamicSequenceSummary generateDynamicSequence(const DynamicSequenceOptions& options,
                                               const std::vector<PersonSprite>& sprites);

}  // namespace edgeslam
