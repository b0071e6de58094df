#include "nav/navigator.h"

#include <gtest/gtest.h>

#include <cmath>

namespace edgeslam {
namespace {

// A route on the ground plane y = 0 (up = -y): 1 m along +z, then 1 m along +x.
RouteRecord corner() {
  RouteRecord route;
  route.name = "corner";
  route.spacing_m = 1.0;
  route.checkpoints = {{0, 0, 0}, {0, 0, 1}, {1, 0, 1}};
  return route;
}

// An upright camera at `centre` facing `yaw_deg` from +z, turned towards +x for positive yaw
// (x right, y down, z forward: turning right is towards +x seen from above, up = -y).
SE3d cameraAt(const Eigen::Vector3d& centre, double yaw_deg) {
  const Eigen::Quaterniond yaw(Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  return SE3d(yaw, centre).inverse();  // T_cw
}

NavigatorOptions options(double reach_radius_m, double off_route_m = 1.0,
                         std::size_t look_ahead = 0) {
  NavigatorOptions o;
  o.reach_radius_m = reach_radius_m;
  o.off_route_m = off_route_m;
  o.look_ahead = look_ahead;
  return o;
}

TEST(Navigator, ReachesCheckpointsInOrderAndArrives) {
  Navigator navigator(corner());
  EXPECT_DOUBLE_EQ(navigator.reachRadius(), 0.5);
  Instruction first = navigator.update(cameraAt({0, 0, 0.1}, 0));
  EXPECT_EQ(first.kind, InstructionKind::kCheckpointReached);
  EXPECT_EQ(first.checkpoint, 0u);
  const Instruction ahead = navigator.update(cameraAt({0, 0, 0.3}, 0));
  EXPECT_EQ(ahead.kind, InstructionKind::kGoStraight);
  EXPECT_EQ(ahead.checkpoint, 1u);
  EXPECT_NEAR(ahead.distance_m, 0.7, 1e-9);
  EXPECT_EQ(navigator.update(cameraAt({0, 0, 0.8}, 0)).kind, InstructionKind::kCheckpointReached);
  EXPECT_EQ(navigator.update(cameraAt({0.9, 0, 1}, 90)).kind, InstructionKind::kCheckpointReached);
  EXPECT_EQ(navigator.update(cameraAt({1, 0, 1}, 90)).kind, InstructionKind::kArrived);
  EXPECT_EQ(navigator.reached(), (std::vector<std::size_t>{0, 1, 2}));
}

TEST(Navigator, TurnsAreSignedAboutUpAndSized) {
  Navigator navigator(corner());
  navigator.update(cameraAt({0, 0, 0}, 0));
  navigator.update(cameraAt({0, 0, 1}, 0));  // checkpoint 2 reached; the next is at +x
  // Facing +z, the next checkpoint is 90 degrees to the right.
  const Instruction right = navigator.update(cameraAt({0, 0, 1.0}, 0));
  ASSERT_EQ(right.kind, InstructionKind::kTurnRight);
  EXPECT_NEAR(right.turn_deg, 90.0, 1e-6);
  // Facing +x (yawed right by 90), straight on; facing -x, turned fully round.
  EXPECT_EQ(navigator.update(cameraAt({0, 0, 1.0}, 90)).kind, InstructionKind::kGoStraight);
  const Instruction left = navigator.update(cameraAt({0, 0, 1.0}, 150));
  ASSERT_EQ(left.kind, InstructionKind::kTurnLeft);
  EXPECT_NEAR(left.turn_deg, 60.0, 1e-6);
  EXPECT_NE(left.text(3).find("turn left by 60 deg to checkpoint 3 of 3"), std::string::npos)
      << left.text(3);
}

TEST(Navigator, FarFromTheRouteIsOffRouteAndNoPoseIsNoInstruction) {
  Navigator navigator(corner(), options(0.2, 0.5));
  EXPECT_EQ(navigator.update(std::nullopt).kind, InstructionKind::kNoPose);
  navigator.update(cameraAt({0, 0, 0}, 0));
  const Instruction off = navigator.update(cameraAt({1.2, 0, 0.5}, 0));
  EXPECT_EQ(off.kind, InstructionKind::kOffRoute);
  // Nearest on the legs into and out of the next checkpoint: the route's corner's end (1, 0, 1).
  EXPECT_NEAR(off.distance_m, std::sqrt(0.2 * 0.2 + 0.5 * 0.5), 1e-9);
  EXPECT_EQ(navigator.offRouteUpdates(), 1u);
  // Back near the leg: guided again.
  EXPECT_NE(navigator.update(cameraAt({0.1, 0, 0.5}, 0)).kind, InstructionKind::kOffRoute);
}

TEST(Navigator, InOrderByDefaultSoAPathCrossingItselfDoesNotSkip) {
  RouteRecord loop = corner();
  loop.checkpoints = {{0, 0, 0}, {0, 0, 2}, {2, 0, 2}, {0, 0, 0.4}};  // the last is near the first
  Navigator in_order(loop, options(0.3));
  in_order.update(cameraAt({0, 0, 0}, 0));
  // Passing near checkpoint 4 on the way to checkpoint 2 does not count it.
  EXPECT_NE(in_order.update(cameraAt({0, 0, 0.4}, 0)).kind, InstructionKind::kCheckpointReached);
  EXPECT_EQ(in_order.nextCheckpoint(), 1u);
  Navigator skipping(loop, options(0.3, 1.0, 2));
  skipping.update(cameraAt({0, 0, 0}, 0));
  EXPECT_EQ(skipping.update(cameraAt({0, 0, 0.4}, 0)).checkpoint, 3u);
}

TEST(Navigator, ACameraPassingSeveralCheckpointsBetweenTwoPosesReachesThemAll) {
  // A car at 10 m/s and 10 fps on a route of checkpoints every 0.5 m: 1 m between poses, two
  // checkpoints a frame, none of them nearer a pose than the 0.25 m reach radius but the first.
  RouteRecord road = corner();
  road.spacing_m = 0.5;
  road.checkpoints.clear();
  for (int i = 0; i <= 8; ++i) road.checkpoints.push_back({0.1, 0, 0.5 * i + 0.1});
  Navigator navigator(road);
  EXPECT_DOUBLE_EQ(navigator.reachRadius(), 0.25);
  EXPECT_EQ(navigator.update(cameraAt({0, 0, 0}, 0)).checkpoint, 0u);
  for (int frame = 1; frame <= 4; ++frame) {
    const Instruction passed = navigator.update(cameraAt({0, 0, 1.0 * frame}, 0));
    ASSERT_EQ(passed.kind, InstructionKind::kCheckpointReached) << "frame " << frame;
    EXPECT_EQ(passed.first_checkpoint, 2u * static_cast<std::size_t>(frame) - 1);
    EXPECT_EQ(passed.checkpoint, 2u * static_cast<std::size_t>(frame));
    // Reaching checkpoints every frame, the driver is still told the way on.
    if (frame < 4) {
      ASSERT_TRUE(passed.then);
      EXPECT_EQ(passed.then->kind, InstructionKind::kGoStraight);
      EXPECT_EQ(passed.then->checkpoint, passed.checkpoint + 1);
      EXPECT_EQ(passed.text(9).rfind("checkpoints ", 0), 0u) << passed.text(9);
      EXPECT_NE(passed.text(9).find("reached; go straight to checkpoint"), std::string::npos)
          << passed.text(9);
    } else {
      EXPECT_FALSE(passed.then);  // the last one: nothing ahead
    }
  }
  EXPECT_EQ(navigator.reached().size(), 9u);
  EXPECT_EQ(navigator.update(cameraAt({0, 0, 5}, 0)).kind, InstructionKind::kArrived);
  Instruction two;
  two.kind = InstructionKind::kCheckpointReached;
  two.first_checkpoint = 1;
  two.checkpoint = 2;
  EXPECT_EQ(two.text(9), "checkpoints 2-3 of 9 reached");
  // A pose lost in between: the path is not drawn across the gap.
  Navigator gap(road);
  gap.update(cameraAt({0, 0, 0}, 0));
  gap.update(std::nullopt);
  EXPECT_NE(gap.update(cameraAt({0, 0, 1.0}, 0)).kind, InstructionKind::kCheckpointReached);
}

TEST(Instruction, DistancesAreInTheMapsUnit) {
  Instruction turn;
  turn.kind = InstructionKind::kTurnRight;
  turn.checkpoint = 3;
  turn.turn_deg = 40;
  turn.distance_m = 0.05;
  EXPECT_EQ(turn.text(9), "turn right by 40 deg to checkpoint 4 of 9 (0.05 m)");
  // A monocular map has no metric scale: its distances are not metres.
  EXPECT_EQ(turn.text(9, "map units"),
            "turn right by 40 deg to checkpoint 4 of 9 (0.05 map units)");
  Instruction reached;
  reached.kind = InstructionKind::kCheckpointReached;
  reached.checkpoint = 2;
  reached.first_checkpoint = 2;
  reached.then = Instruction::Heading{InstructionKind::kGoStraight, 3, 0.0, 0.04};
  EXPECT_EQ(reached.text(9, "map units"),
            "checkpoint 3 of 9 reached; go straight to checkpoint 4 of 9 (0.04 map units)");
  Instruction off;
  off.kind = InstructionKind::kOffRoute;
  off.distance_m = 1.5;
  EXPECT_EQ(off.text(9, "map units"), "off route (1.50 map units from it)");
}

TEST(Navigator, BadRoutesAndOptionsAreRefused) {
  RouteRecord empty = corner();
  empty.checkpoints.clear();
  EXPECT_THROW(Navigator{empty}, std::invalid_argument);
  EXPECT_THROW(Navigator(corner(), options(0.0, 0.0)), std::invalid_argument);
  NavigatorOptions wide;
  wide.straight_within_deg = 200.0;
  EXPECT_THROW(Navigator(corner(), wide), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
