#pragma once
// A live one-line progress display: rewritten in place on a terminal, printed every few seconds
// otherwise.
#include <chrono>
#include <cstdio>
#include <string>

namespace edgeslam::cli {

class ProgressLine {
 public:
  explicit ProgressLine(std::FILE* stream = stderr);
  ~ProgressLine();
  // Shows `text`; throttled to ~10 Hz on a terminal and one line per `log_period` otherwise.
  void update(const std::string& text, bool force = false);
  void finish();

 private:
  std::FILE* stream_;
  bool is_terminal_;
  bool dirty_ = false;
  std::chrono::steady_clock::time_point last_;
  std::chrono::milliseconds period_;
};

}  // namespace edgeslam::cli
