#include "nav/route_making.h"

#include <gtest/gtest.h>

#include <optional>
#include <stdexcept>

namespace edgeslam {
namespace {

// A camera upright (y down) at `centre`, looking along +z.
KeyFrameRecord keyFrameAt(std::uint64_t frame, const Eigen::Vector3d& centre) {
  KeyFrameRecord keyframe;
  keyframe.id = frame;
  keyframe.frame_index = frame;
  keyframe.T_cw = SE3d(Eigen::Quaterniond::Identity(), centre).inverse();
  return keyframe;
}

// An L-shaped walk: 2 m along x, then 1 m along z, keyframes every 0.3 m, given out of order.
StoredSession lWalk() {
  StoredSession session;
  session.id = 7;
  std::uint64_t frame = 0;
  for (double x = 0.0; x < 2.0 - 1e-9; x += 0.3)
    session.keyframes.push_back(keyFrameAt(frame++ * 10, {x, 0, 0}));
  for (double z = 0.0; z <= 1.0 + 1e-9; z += 0.25)
    session.keyframes.push_back(keyFrameAt(frame++ * 10, {2.0, 0, z}));
  std::swap(session.keyframes[1], session.keyframes[5]);
  return session;
}

RouteAlongKeyFramesOptions every(double spacing_m, std::optional<std::uint64_t> first = {},
                                 std::optional<std::uint64_t> last = {}) {
  RouteAlongKeyFramesOptions options;
  options.spacing_m = spacing_m;
  options.first_frame = first;
  options.last_frame = last;
  return options;
}

TEST(RouteMaking, CheckpointsAreEvenlySpacedAlongThePathAndEndAtItsEnd) {
  const RouteRecord route = routeAlongKeyFrames(lWalk(), every(0.5));
  // 3 m of path: checkpoints at 0, 0.5, ..., 3.0 m of it.
  ASSERT_EQ(route.checkpoints.size(), 7u);
  for (std::size_t i = 1; i < route.checkpoints.size(); ++i) {
    // Along the path, not as the crow flies: the corner checkpoint is on the corner.
    EXPECT_LE((route.checkpoints[i] - route.checkpoints[i - 1]).norm(), 0.5 + 1e-9);
  }
  EXPECT_TRUE(route.checkpoints.front().isApprox(Eigen::Vector3d(0, 0, 0)));
  EXPECT_TRUE(route.checkpoints[4].isApprox(Eigen::Vector3d(2.0, 0, 0)));
  EXPECT_TRUE(route.checkpoints.back().isApprox(Eigen::Vector3d(2.0, 0, 1.0)));
  // Upright cameras: up is -y of the map.
  EXPECT_TRUE(route.up.isApprox(-Eigen::Vector3d::UnitY()));
  EXPECT_EQ(route.spacing_m, 0.5);
  EXPECT_NE(route.source.find("session 7"), std::string::npos);
}

TEST(RouteMaking, AFrameRangeTakesOnlyItsKeyFrames) {
  const RouteRecord route = routeAlongKeyFrames(lWalk(), every(0.25, 70, 1000));
  // Only the 1 m leg along z.
  EXPECT_TRUE(route.checkpoints.front().isApprox(Eigen::Vector3d(2.0, 0, 0)));
  EXPECT_TRUE(route.checkpoints.back().isApprox(Eigen::Vector3d(2.0, 0, 1.0)));
  EXPECT_EQ(route.checkpoints.size(), 5u);
  EXPECT_NE(route.source.find("frames 70-"), std::string::npos) << route.source;
}

TEST(RouteMaking, TooFewKeyFramesOrTooShortAPathOrNoSpacingAreErrors) {
  EXPECT_THROW(routeAlongKeyFrames(lWalk(), every(0.0)), std::invalid_argument);
  EXPECT_THROW(routeAlongKeyFrames(lWalk(), every(10.0)), std::invalid_argument);
  EXPECT_THROW(routeAlongKeyFrames(lWalk(), every(0.5, 0, 5)), std::invalid_argument);
}

TEST(RouteMaking, UpFollowsTheCamerasAndFallsBackWhenTheyDisagree) {
  std::vector<KeyFrameRecord> tilted;
  // Cameras rolled 90 degrees about their optical axis: their "up" is world +x.
  const Eigen::Quaterniond roll(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()));
  for (int i = 0; i < 3; ++i) {
    KeyFrameRecord k;
    k.T_cw = SE3d(roll, Eigen::Vector3d(i, 0, 0)).inverse();
    tilted.push_back(k);
  }
  const Eigen::Vector3d up = upOfKeyFrames(tilted);
  EXPECT_NEAR(std::abs(up.x()), 1.0, 1e-9) << up.transpose();
  std::vector<KeyFrameRecord> opposite = {keyFrameAt(0, {0, 0, 0}), keyFrameAt(1, {1, 0, 0})};
  opposite[1].T_cw = SE3d(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ())),
                          Eigen::Vector3d::Zero());
  EXPECT_TRUE(upOfKeyFrames(opposite).isApprox(-Eigen::Vector3d::UnitY()));
}

TEST(RouteMaking, PositionsParseOnePerLineAndBadLinesAreNamed) {
  const auto points = parseCheckpointPositions("# x y z\n0 0 0\n\n1.5 -2 3e-1\n");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_TRUE(points[1].isApprox(Eigen::Vector3d(1.5, -2, 0.3)));
  try {
    parseCheckpointPositions("0 0 0\n1 2\n");
    FAIL() << "a line of two numbers was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parseCheckpointPositions("1 2 3 4\n"), std::invalid_argument);
  EXPECT_THROW(parseCheckpointPositions("1 nan 3\n"), std::invalid_argument);
  EXPECT_THROW(parseCheckpointPositions("# nothing\n"), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
