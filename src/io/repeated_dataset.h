#pragma once
// A sequence played several times in a row (`run --repeat N`): the camera jumps from the last
// frame back to the first at each pass boundary, as a user who maps a place and comes back to it.
#include <cstddef>
#include <memory>

#include "io/dataset.h"

namespace edgeslam {

// Frame p * count + i of the result is frame i of `reader` in pass p (0-based). Timestamps go on
// increasing: pass p's are the sequence's shifted by p times (its duration plus one frame
// interval), so that each pass is timed like the first and frames stay in time order. Ground truth
// and file names are the sequence's. `passes` == 1 returns `reader` itself; 0 throws
// std::invalid_argument.
std::unique_ptr<DatasetReader> repeatFrames(std::unique_ptr<DatasetReader> reader,
                                            std::size_t passes);

// The pass (0-based) frame `index` of a sequence of `frames_per_pass` frames played repeatedly
// falls in.
inline std::size_t passOfFrame(std::size_t index, std::size_t frames_per_pass) {
  return frames_per_pass == 0 ? 0 : index / frames_per_pass;
}

}  // namespace edgeslam
