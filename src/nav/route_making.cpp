#include "nav/route_making.h"

#include <fmt/format.h>

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace edgeslam {
namespace {

Eigen::Vector3d cameraCentre(const KeyFrameRecord& keyframe) {
  return keyframe.T_cw.inverse().translation();
}

}  // namespace

Eigen::Vector3d upOfKeyFrames(const std::vector<KeyFrameRecord>& keyframes) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const KeyFrameRecord& keyframe : keyframes) {
    sum -= keyframe.T_cw.inverse().rotationMatrix().col(1);
  }
  if (keyframes.empty() || sum.norm() < 0.5 * static_cast<double>(keyframes.size())) {
    return -Eigen::Vector3d::UnitY();
  }
  return sum.normalized();
}

RouteRecord routeAlongKeyFrames(const StoredSession& session,
                                const RouteAlongKeyFramesOptions& options) {
  if (!(options.spacing_m > 0.0)) {
    throw std::invalid_argument("the spacing of checkpoints must be positive");
  }
  std::vector<KeyFrameRecord> path;
  for (const KeyFrameRecord& keyframe : session.keyframes) {
    if (options.first_frame && keyframe.frame_index < *options.first_frame) continue;
    if (options.last_frame && keyframe.frame_index > *options.last_frame) continue;
    path.push_back(keyframe);
  }
  std::sort(path.begin(), path.end(), [](const KeyFrameRecord& a, const KeyFrameRecord& b) {
    return a.frame_index < b.frame_index;
  });
  if (path.size() < 2) {
    throw std::invalid_argument(fmt::format(
        "a route needs at least two keyframes of the session in range; there are {}", path.size()));
  }
  RouteRecord route;
  route.spacing_m = options.spacing_m;
  route.up = upOfKeyFrames(path);
  route.source = fmt::format("keyframes of session {}, frames {}-{}", session.id,
                             path.front().frame_index, path.back().frame_index);
  route.checkpoints.push_back(cameraCentre(path.front()));
  double to_next = options.spacing_m;  // path length left until the next checkpoint
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector3d from = cameraCentre(path[i - 1]);
    const Eigen::Vector3d to = cameraCentre(path[i]);
    const double segment = (to - from).norm();
    length += segment;
    double along = 0.0;
    while (segment - along >= to_next) {
      along += to_next;
      route.checkpoints.push_back(from + (to - from) * (along / segment));
      to_next = options.spacing_m;
    }
    to_next -= segment - along;
  }
  if (length < options.spacing_m) {
    throw std::invalid_argument(
        fmt::format("the keyframe path in range is {:.2f} m long, shorter than one spacing "
                    "({:.2f} m)",
                    length, options.spacing_m));
  }
  // The path's end is the last checkpoint, unless the last one placed is already next to it.
  const Eigen::Vector3d end = cameraCentre(path.back());
  if ((end - route.checkpoints.back()).norm() > 0.25 * options.spacing_m) {
    route.checkpoints.push_back(end);
  }
  return route;
}

std::vector<Eigen::Vector3d> parseCheckpointPositions(const std::string& text) {
  std::vector<Eigen::Vector3d> out;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    Eigen::Vector3d p;
    std::string rest;
    if (!(fields >> p.x() >> p.y() >> p.z()) || (fields >> rest) || !p.allFinite()) {
      throw std::invalid_argument(
          fmt::format("line {}: expected three numbers \"x y z\", got \"{}\"", number, line));
    }
    out.push_back(p);
  }
  if (out.empty()) throw std::invalid_argument("no positions given");
  return out;
}

}  // namespace edgeslam
