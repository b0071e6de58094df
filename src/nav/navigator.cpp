#include "nav/navigator.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "nav/path_distance.h"

namespace edgeslam {
namespace {

Eigen::Vector3d onGround(const Eigen::Vector3d& v, const Eigen::Vector3d& up) {
  return v - v.dot(up) * up;
}

}  // namespace

void NavigatorOptions::check() const {
  if (!(reach_radius_m >= 0.0) || !(off_route_m > 0.0) || !(straight_within_deg >= 0.0) ||
      !(straight_within_deg < 180.0)) {
    throw std::invalid_argument(
        "navigator: reach radius >= 0, off-route distance > 0 and straight tolerance in "
        "[0, 180) degrees");
  }
}

const char* toString(InstructionKind kind) {
  switch (kind) {
    case InstructionKind::kNoPose:
      return "no_pose";
    case InstructionKind::kGoStraight:
      return "straight";
    case InstructionKind::kTurnLeft:
      return "left";
    case InstructionKind::kTurnRight:
      return "right";
    case InstructionKind::kCheckpointReached:
      return "checkpoint";
    case InstructionKind::kOffRoute:
      return "off_route";
    case InstructionKind::kArrived:
      return "arrived";
  }
  return "?";
}

std::string Instruction::text(std::size_t checkpoints, std::string_view unit) const {
  if (kind == InstructionKind::kCheckpointReached && then) {
    Instruction next;
    next.kind = then->kind;
    next.checkpoint = then->checkpoint;
    next.turn_deg = then->turn_deg;
    next.distance_m = then->distance_m;
    Instruction reached = *this;
    reached.then.reset();
    return reached.text(checkpoints, unit) + "; " + next.text(checkpoints, unit);
  }
  switch (kind) {
    case InstructionKind::kNoPose:
      return "localising...";
    case InstructionKind::kGoStraight:
      return fmt::format("go straight to checkpoint {} of {} ({:.2f} {})", checkpoint + 1,
                         checkpoints, distance_m, unit);
    case InstructionKind::kTurnLeft:
    case InstructionKind::kTurnRight:
      return fmt::format("turn {} by {:.0f} deg to checkpoint {} of {} ({:.2f} {})",
                         kind == InstructionKind::kTurnLeft ? "left" : "right", turn_deg,
                         checkpoint + 1, checkpoints, distance_m, unit);
    case InstructionKind::kCheckpointReached:
      if (first_checkpoint < checkpoint) {
        return fmt::format("checkpoints {}-{} of {} reached", first_checkpoint + 1, checkpoint + 1,
                           checkpoints);
      }
      return fmt::format("checkpoint {} of {} reached", checkpoint + 1, checkpoints);
    case InstructionKind::kOffRoute:
      return fmt::format("off route ({:.2f} {} from it)", distance_m, unit);
    case InstructionKind::kArrived:
      return fmt::format("arrived: all {} checkpoints behind", checkpoints);
  }
  return "";
}

Navigator::Navigator(RouteRecord route, NavigatorOptions options)
    : route_(std::move(route)), options_(options) {
  options_.check();
  if (route_.checkpoints.empty()) throw std::invalid_argument("the route has no checkpoints");
  if (!(route_.up.norm() > 0.0)) throw std::invalid_argument("the route has no up direction");
  route_.up.normalize();
  reach_radius_m_ = options_.reach_radius_m > 0.0 ? options_.reach_radius_m
                    : route_.spacing_m > 0.0      ? 0.5 * route_.spacing_m
                                                  : 0.25;
}

double Navigator::distanceToRoute(const Eigen::Vector3d& position) const {
  const auto& points = route_.checkpoints;
  if (points.size() == 1) return (points[0] - position).norm();
  // The legs around where the walker should be: the one into the next checkpoint and one on.
  const std::size_t first = next_ == 0 ? 0 : next_ - 1;
  const std::size_t last = std::min(points.size() - 1, next_ + 1 + options_.look_ahead);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = first; i < last; ++i) {
    best = std::min(best, distanceToSegment(position, points[i], points[i + 1]));
  }
  return best;
}

Instruction Navigator::update(const std::optional<SE3d>& T_cw) {
  Instruction out;
  const std::size_t count = route_.checkpoints.size();
  if (next_ >= count) {
    out.kind = InstructionKind::kArrived;
    out.checkpoint = count - 1;
    return out;
  }
  if (!T_cw) {
    previous_position_.reset();
    return out;
  }
  const SE3d T_wc = T_cw->inverse();
  const Eigen::Vector3d position = T_wc.translation();
  const Eigen::Vector3d from = previous_position_.value_or(position);
  previous_position_ = position;
  const auto passedWithin = [&](std::size_t k) {
    return distanceToSegment(route_.checkpoints[k], from, position) <= reach_radius_m_;
  };
  // Reached: the farthest checkpoint within reach among the next few, then the ones right after
  // it that the path since the last pose passed too.
  const std::size_t last = std::min(count - 1, next_ + options_.look_ahead);
  for (std::size_t k = last + 1; k-- > next_;) {
    if (!passedWithin(k)) continue;
    out.first_checkpoint = k;
    while (k + 1 < count && passedWithin(k + 1)) ++k;
    for (std::size_t j = out.first_checkpoint; j <= k; ++j) reached_.push_back(j);
    next_ = k + 1;
    out.kind = InstructionKind::kCheckpointReached;
    out.checkpoint = k;
    out.distance_m = (route_.checkpoints[k] - position).norm();
    if (next_ < count) out.then = headingTo(T_wc);
    return out;
  }
  const double off = distanceToRoute(position);
  if (off > options_.off_route_m) {
    ++off_route_updates_;
    out.kind = InstructionKind::kOffRoute;
    out.checkpoint = next_;
    out.distance_m = off;
    return out;
  }
  const Instruction::Heading heading = headingTo(T_wc);
  out.kind = heading.kind;
  out.checkpoint = heading.checkpoint;
  out.turn_deg = heading.turn_deg;
  out.distance_m = heading.distance_m;
  return out;
}

Instruction::Heading Navigator::headingTo(const SE3d& T_wc) const {
  Instruction::Heading out;
  const Eigen::Vector3d& up = route_.up;
  const Eigen::Vector3d to_checkpoint = route_.checkpoints[next_] - T_wc.translation();
  const Eigen::Vector3d heading = onGround(T_wc.rotationMatrix().col(2), up);
  const Eigen::Vector3d bearing = onGround(to_checkpoint, up);
  out.checkpoint = next_;
  out.distance_m = to_checkpoint.norm();
  if (heading.norm() < 1e-6 || bearing.norm() < 1e-6) {
    return out;  // go straight: looking straight up or down, or on top of it
  }
  // Counter-clockwise about up (seen from above) is to the left.
  const double angle =
      std::atan2(up.dot(heading.cross(bearing)), heading.dot(bearing)) * 180.0 / std::numbers::pi;
  if (std::abs(angle) > options_.straight_within_deg) {
    out.kind = angle > 0.0 ? InstructionKind::kTurnLeft : InstructionKind::kTurnRight;
    out.turn_deg = std::abs(angle);
  }
  return out;
}

}  // namespace edgeslam
