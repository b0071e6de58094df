#include "progress_line.h"

#include <unistd.h>

namespace edgeslam::cli {

ProgressLine::ProgressLine(std::FILE* stream)
    : stream_(stream),
      is_terminal_(isatty(fileno(stream)) != 0),
      last_(std::chrono::steady_clock::now() - std::chrono::hours(1)),
      period_(is_terminal_ ? std::chrono::milliseconds(100) : std::chrono::milliseconds(2000)) {}

ProgressLine::~ProgressLine() {
  finish();
}

void ProgressLine::update(const std::string& text, bool force) {
  const auto now = std::chrono::steady_clock::now();
  if (!force && now - last_ < period_) return;
  last_ = now;
  if (is_terminal_) {
    std::fprintf(stream_, "\r\033[K%s", text.c_str());
    dirty_ = true;
  } else {
    std::fprintf(stream_, "%s\n", text.c_str());
  }
  std::fflush(stream_);
}

void ProgressLine::finish() {
  if (dirty_) {
    std::fprintf(stream_, "\n");
    std::fflush(stream_);
    dirty_ = false;
  }
}

}  // namespace edgeslam::cli
