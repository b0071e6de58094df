#pragma once
// Turn-by-turn guidance along a route, as in the paper's robot study: from each pose the client
// reports, the next instruction (go straight / turn by an angle / checkpoint reached / off route).
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/se3.h"
#include "store/map_store.h"

namespace edgeslam {

struct NavigatorOptions {
  // A checkpoint is reached when the estimated path comes this close (0: half the route's
  // spacing, or 0.25 m for a route of given positions). The path between two poses in a row
  // counts: a car at 10 m/s and 10 fps moves 1 m a frame, past checkpoints 0.5 m apart.
  double reach_radius_m = 0.0;
  double off_route_m = 1.0;  // farther than this from the route's next legs: off route
  double straight_within_deg = 20.0;
  // Later checkpoints that count as reached too, skipping those before (a walker cutting a corner
  // past one). 0: in order only, the default, since a path that crosses itself (a room walked
  // round) passes near later checkpoints early.
  std::size_t look_ahead = 0;
  void check() const;  // throws std::invalid_argument
};

enum class InstructionKind {
  kNoPose,  // not localised: no instruction
  kGoStraight,
  kTurnLeft,
  kTurnRight,
  kCheckpointReached,
  kOffRoute,
  kArrived,  // every checkpoint is behind
};

const char* toString(InstructionKind kind);

struct Instruction {
  InstructionKind kind = InstructionKind::kNoPose;
  std::size_t checkpoint = 0;  // 0-based: the one reached, or the next one to go to
  // kCheckpointReached: the first checkpoint reached by this update; the ones from it to
  // `checkpoint` were all passed since the last pose.
  std::size_t first_checkpoint = 0;
  double turn_deg = 0.0;    // by how much to turn (positive), for kTurnLeft/kTurnRight
  double distance_m = 0.0;  // to the checkpoint, or from the route when off it
  // kCheckpointReached with checkpoints still ahead: the way on to the next one (go straight or
  // turn), so that a camera reaching checkpoints every frame is still told where to go.
  struct Heading {
    InstructionKind kind = InstructionKind::kGoStraight;
    std::size_t checkpoint = 0;
    double turn_deg = 0.0;
    double distance_m = 0.0;
  };
  std::optional<Heading> then;
  // One line for people: "turn left by 35 deg to checkpoint 4 of 12 (1.20 m)", or
  // "checkpoint 3 of 12 reached; go straight to checkpoint 4 of 12 (0.50 m)". `unit`: of the
  // map's distances ("map units" for a monocular map, which has no metric scale).
  std::string text(std::size_t checkpoints, std::string_view unit = "m") const;
};

class Navigator {
 public:
  // Throws std::invalid_argument for a route without checkpoints or bad options.
  Navigator(RouteRecord route, NavigatorOptions options = {});

  // `T_cw`: the camera's pose in the map's frame this frame, if it has one.
  Instruction update(const std::optional<SE3d>& T_cw);

  const RouteRecord& route() const { return route_; }
  double reachRadius() const { return reach_radius_m_; }
  std::size_t nextCheckpoint() const { return next_; }
  // Checkpoints the navigator saw reached (by the estimated pose), in order; skipped ones are
  // not in it.
  const std::vector<std::size_t>& reached() const { return reached_; }
  std::size_t offRouteUpdates() const { return off_route_updates_; }

 private:
  double distanceToRoute(const Eigen::Vector3d& position) const;
  // Go straight or turn, towards checkpoint `next_`, from the camera pose `T_wc`.
  Instruction::Heading headingTo(const SE3d& T_wc) const;

  RouteRecord route_;
  NavigatorOptions options_;
  double reach_radius_m_ = 0.0;
  std::size_t next_ = 0;
  std::optional<Eigen::Vector3d> previous_position_;  // the last update's, when it had a pose
  std::vector<std::size_t> reached_;
  std::size_t off_route_updates_ = 0;
};

}  // namespace edgeslam
