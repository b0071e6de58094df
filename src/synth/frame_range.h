#pragma once
// An inclusive range of frame indices written "A-B" on the command line.
#include <cstddef>
#include <string>

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

}  // namespace edgeslam
