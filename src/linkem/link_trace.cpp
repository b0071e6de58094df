#include "linkem/link_trace.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace edgeslam {
namespace {

LinkSettings apply(const LinkTracePoint& point, LinkSettings settings) {
  settings.up_mbps = point.up_mbps;
  settings.down_mbps = point.down_mbps;
  settings.delay_up_ms = point.delay_up_ms;
  settings.delay_down_ms = point.delay_down_ms;
  if (point.jitter_ms) settings.jitter_ms = *point.jitter_ms;
  if (point.loss) settings.loss = *point.loss;
  return settings;
}

double parseNumber(const std::string& token, const char* column) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(token, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != token.size() || !std::isfinite(value)) {
    throw std::invalid_argument(fmt::format("{} '{}' is not a number", column, token));
  }
  return value;
}

}  // namespace

LinkTrace::LinkTrace(std::vector<LinkTracePoint> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("a link trace needs at least one point");
  if (points_.front().time_s != 0.0) {
    throw std::invalid_argument(
        fmt::format("a link trace starts at time 0, not {}", points_.front().time_s));
  }
  for (std::size_t i = 0; i < points_.size(); ++i) {
    const LinkTracePoint& p = points_[i];
    if (i > 0 && !(p.time_s > points_[i - 1].time_s)) {
      throw std::invalid_argument(
          fmt::format("trace time {} does not follow {} (times must increase)", p.time_s,
                      points_[i - 1].time_s));
    }
    validate(apply(p, LinkSettings{}));
  }
  const double last_step =
      points_.size() > 1 ? points_.back().time_s - points_[points_.size() - 2].time_s : 1.0;
  period_s_ = points_.back().time_s + last_step;
}

LinkTrace LinkTrace::load(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(fmt::format("cannot open link trace {}", file.string()));
  return parse(in, file.string());
}

LinkTrace LinkTrace::parse(std::istream& in, const std::string& source_name) {
  static constexpr const char* kColumns[] = {
      "time_s", "up_mbps", "down_mbps", "delay_up_ms", "delay_down_ms", "jitter_ms", "loss"};
  std::vector<LinkTracePoint> points;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::vector<std::string> tokens;
    for (std::string token; words >> token;) tokens.push_back(token);
    if (tokens.empty()) continue;
    try {
      if (tokens.size() < 5 || tokens.size() > 7) {
        throw std::invalid_argument(fmt::format(
            "expected 5 to 7 columns (time_s up_mbps down_mbps delay_up_ms delay_down_ms "
            "[jitter_ms [loss]]), got {}",
            tokens.size()));
      }
      double values[7] = {};
      for (std::size_t i = 0; i < tokens.size(); ++i)
        values[i] = parseNumber(tokens[i], kColumns[i]);
      LinkTracePoint p{values[0], values[1], values[2], values[3], values[4], {}, {}};
      if (tokens.size() >= 6) p.jitter_ms = values[5];
      if (tokens.size() >= 7) p.loss = values[6];
      validate(apply(p, LinkSettings{}));
      if (p.time_s < 0.0) throw std::invalid_argument("time_s must be >= 0");
      if (points.empty() && p.time_s != 0.0) {
        throw std::invalid_argument(
            fmt::format("the first point must be at time 0, not {}", p.time_s));
      }
      if (!points.empty() && !(p.time_s > points.back().time_s)) {
        throw std::invalid_argument(fmt::format("time {} does not follow {} (times must increase)",
                                                p.time_s, points.back().time_s));
      }
      points.push_back(p);
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(fmt::format("{}:{}: {}", source_name, line_number, e.what()));
    }
  }
  if (points.empty()) {
    throw std::runtime_error(fmt::format("{}: link trace has no points", source_name));
  }
  return LinkTrace(std::move(points));
}

const LinkTracePoint& LinkTrace::pointAt(double elapsed_s) const {
  double t = std::fmod(std::max(0.0, elapsed_s), period_s_);
  // The last point whose time is <= t.
  const auto after =
      std::upper_bound(points_.begin(), points_.end(), t,
                       [](double time, const LinkTracePoint& p) { return time < p.time_s; });
  return *(after - 1);
}

LinkSettings LinkTrace::settingsAt(double elapsed_s, const LinkSettings& base) const {
  return apply(pointAt(elapsed_s), base);
}

}  // namespace edgeslam
