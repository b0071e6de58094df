#pragma once
// An inclusive range of frame indices written "A-B" on the command line (`run --frames`,
// `synth-dynamic --frames`): a stretch of a dataset played as if it were the whole sequence, so
// that one recording can stand in for several sessions.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "io/dataset.h"

namespace edgeslam {

struct FrameRange {
  std::size_t first = 0;
  std::size_t last = 0;  // inclusive
  std::size_t count() const { return last - first + 1; }
};

// "A-B" with A <= B (non-negative integers). Throws std::invalid_argument quoting the text.
FrameRange parseFrameRange(const std::string& text);

// Throws std::invalid_argument when the range does not fit a sequence of `frame_count` frames.
void checkFrameRange(const FrameRange& range, std::size_t frame_count);

// Frames first..last of `reader` as frames 0..count-1, with their original timestamps, ground
// truth and file names. Throws std::invalid_argument (checkFrameRange) when they do not fit.
std::unique_ptr<DatasetReader> selectFrames(std::unique_ptr<DatasetReader> reader,
                                            const FrameRange& range);

// "A-B" or several such ranges, comma-separated ("0-200,375-999"). Throws std::invalid_argument
// quoting the text.
std::vector<FrameRange> parseFrameRanges(const std::string& text);

// Several stretches played one after the other as one sequence: a cut between two is a camera
// that is elsewhere from one frame to the next (kidnapped). The first keeps its timestamps; each
// next one follows the previous one's last frame by one frame interval (its own intervals kept),
// so time always goes on. One range: as above.
std::unique_ptr<DatasetReader> selectFrames(std::unique_ptr<DatasetReader> reader,
                                            const std::vector<FrameRange>& ranges);

}  // namespace edgeslam
