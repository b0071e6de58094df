#pragma once
// A link trace: settings that change over time, replayed in a loop.
//
// File format (plain text, one point per line, '#' starts a comment, blank lines ignored):
//   time_s up_mbps down_mbps delay_up_ms delay_down_ms [jitter_ms [loss]]
// Times start at 0 and increase strictly. A point's values hold until the next point's time; the
// last point holds for as long as the step before it (1 s when the trace has a single point), and
// then the trace starts again from its first point. Rates of 0 mean unlimited. Columns left out
// (jitter, loss) keep the emulator's base settings.
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "linkem/link_settings.h"

namespace edgeslam {

struct LinkTracePoint {
  double time_s = 0.0;
  double up_mbps = 0.0;
  double down_mbps = 0.0;
  double delay_up_ms = 0.0;
  double delay_down_ms = 0.0;
  std::optional<double> jitter_ms;
  std::optional<double> loss;
};

class LinkTrace {
 public:
  // Throws std::invalid_argument when the points are empty, unordered or hold invalid values.
  explicit LinkTrace(std::vector<LinkTracePoint> points);

  // Errors (std::runtime_error) name the file and the line: "trace.txt:7: ...".
  static LinkTrace load(const std::filesystem::path& file);
  static LinkTrace parse(std::istream& in, const std::string& source_name);

  const std::vector<LinkTracePoint>& points() const { return points_; }
  double periodS() const { return period_s_; }
  // The point in effect `elapsed_s` after the replay started (looping).
  const LinkTracePoint& pointAt(double elapsed_s) const;
  // `base` with the trace's values at `elapsed_s` applied.
  LinkSettings settingsAt(double elapsed_s, const LinkSettings& base) const;

 private:
  std::vector<LinkTracePoint> points_;
  double period_s_ = 0.0;
};

}  // namespace edgeslam
