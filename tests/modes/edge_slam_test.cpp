// Edge mode with the edge in the same process: the client's map must stay a faithful replica of
// the edge's global map, and tracking as good as in local mode.
#include "modes/edge_slam.h"

#include <gtest/gtest.h>

#include <set>

#include "eval/ate.h"
#include "io/dataset.h"
#include "modes/in_process_edge_link.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

TEST(EdgeSlam, ClientMapReplicatesTheEdgeMapOnKitti) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  auto reader = openDataset(test::sharedPath("datasets/kitti07-160"));
  const PinholeCamera& camera = reader->camera();
  SlamOptions options = defaultSlamOptions(camera, Sensor::kMonocular);
  EdgeMapSessionOptions edge_options;
  edge_options.backend.threaded = false;
  auto link = std::make_unique<InProcessEdgeLink>(camera, Sensor::kMonocular, edge_options);
  InProcessEdgeLink* raw_link = link.get();
  EdgeSlam slam(camera, options, std::move(link));
  for (std::size_t i = 0; i < 30; ++i) {
    const DatasetFrame frame = reader->load(i);
    slam.process(i, frame.timestamp, frame.gray, frame.depth);
    raw_link->flush();
  }
  slam.finish();
  // What the edge reported in its last slice, and the client's keyframes: these may take the
  // client map's mutex, so before the test holds it.
  const std::size_t reported_keyframes = slam.keyFrameCount();
  const std::size_t reported_points = slam.mapPointCount();
  const Trajectory client_keyframes = slam.keyframeTrajectory();
  Map& edge = raw_link->session().map();
  MutexLock edge_lock(edge.updateMutex());
  MutexLock client_lock(slam.map().updateMutex());
  EXPECT_GT(edge.pointCount(), 300u);
  EXPECT_EQ(slam.map().keyFrameCount(), edge.keyFrameCount());
  EXPECT_EQ(slam.map().heldKeyFrameCount(), edge.keyFrameCount());
  EXPECT_EQ(slam.map().pointCount(), edge.pointCount());
  EXPECT_EQ(reported_keyframes, edge.keyFrameCount());
  EXPECT_EQ(reported_points, edge.pointCount());
  for (MapPoint* p : edge.mapPoints()) {
    const MapPoint* replica = slam.map().mapPoint(p->id());
    ASSERT_NE(replica, nullptr) << "edge point " << p->id() << " missing on the client";
    EXPECT_LT((replica->position() - p->position()).norm(), 1e-9);
    EXPECT_EQ(replica->observations().size(), p->observations().size());
  }
  std::size_t compared = 0;
  for (const auto& pose : client_keyframes) {
    for (KeyFrame* kf : edge.keyFrames()) {
      if (kf->timestamp() != pose.timestamp) continue;
      EXPECT_LT((kf->cameraCenter() - pose.pose.translation()).norm(), 1e-9);
      ++compared;
    }
  }
  EXPECT_EQ(compared, edge.keyFrameCount());
}

// With a bounded client map the client holds exactly the keyframes the edge's window says, every
// point a held keyframe sees (as the edge has it, observations among held keyframes), nothing
// else, and every keyframe's pose, evicted or not.
TEST(EdgeSlam, BoundedClientMapHoldsTheEdgeWindowOnKitti) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  auto reader = openDataset(test::sharedPath("datasets/kitti07-160"));
  const PinholeCamera& camera = reader->camera();
  SlamOptions options = defaultSlamOptions(camera, Sensor::kMonocular);
  EdgeMapSessionOptions edge_options;
  edge_options.backend.threaded = false;
  edge_options.window.keyframes = 6;
  auto link = std::make_unique<InProcessEdgeLink>(camera, Sensor::kMonocular, edge_options);
  InProcessEdgeLink* raw_link = link.get();
  EdgeSlam slam(camera, options, std::move(link));
  std::size_t tracked = 0;
  for (std::size_t i = 0; i < 40; ++i) {
    const DatasetFrame frame = reader->load(i);
    if (slam.process(i, frame.timestamp, frame.gray, frame.depth).state == TrackingState::kOk) {
      ++tracked;
    }
    raw_link->flush();
  }
  slam.finish();
  EXPECT_GE(tracked, 35u);
  const ClientMapSize size = slam.clientMapSize();
  // What the run command reads, through the mode-neutral interface.
  const SlamSystem& system = slam;
  const std::optional<SplitClientReport> report = system.splitClientReport();
  ASSERT_TRUE(report.has_value());
  EXPECT_EQ(report->client_map.keyframes, size.keyframes);
  EXPECT_EQ(report->client_map.keyframes_evicted, size.keyframes_evicted);
  EXPECT_EQ(system.adaptation(), nullptr);  // an in-process link does not adapt
  EdgeMapSession& session = raw_link->session();
  Map& edge = session.map();
  MutexLock edge_lock(edge.updateMutex());
  const Map& client = slam.map();
  MutexLock client_lock(client.updateMutex());
  const std::set<KeyFrameId>& held = session.clientWindow().held();
  ASSERT_GT(edge.keyFrameCount(), held.size()) << "the run must leave the window";
  EXPECT_LE(held.size(), session.clientWindow().keepSize());
  EXPECT_GT(session.stats().client_keyframes_evicted, 0u);
  EXPECT_EQ(client.keyFrameCount(), edge.keyFrameCount());
  EXPECT_EQ(client.heldKeyFrameCount(), held.size());
  for (KeyFrame* kf : edge.keyFrames()) {
    const KeyFrame* replica = client.keyFrame(kf->id());
    ASSERT_NE(replica, nullptr) << "keyframe " << kf->id() << " missing on the client";
    EXPECT_EQ(replica->isEvicted(), !held.contains(kf->id()));
    EXPECT_LT((replica->cameraCenter() - kf->cameraCenter()).norm(), 1e-9);
  }
  // A point the client sees from two held keyframes or fewer may be gone there: applying a slice
  // that drops one of its observations erases such a weak point on the client (map_replication.cpp)
  // even where the edge keeps it with observations in evicted keyframes.
  std::size_t seen_by_held = 0, seen_well_by_held = 0;
  for (MapPoint* p : edge.mapPoints()) {
    std::size_t held_observations = 0;
    for (const auto& [id, obs] : p->observations()) held_observations += held.contains(id);
    const MapPoint* replica = client.mapPoint(p->id());
    if (held_observations == 0) {
      EXPECT_EQ(replica, nullptr) << "point " << p->id() << " seen by no held keyframe";
      continue;
    }
    ++seen_by_held;
    if (held_observations > 2) ++seen_well_by_held;
    if (replica == nullptr) {
      EXPECT_LE(held_observations, 2u)
          << "point " << p->id() << " seen by held keyframes is missing";
      continue;
    }
    EXPECT_LT((replica->position() - p->position()).norm(), 1e-9);
    EXPECT_EQ(replica->observations().size(), held_observations);
  }
  EXPECT_LE(client.pointCount(), seen_by_held);
  EXPECT_GE(client.pointCount(), seen_well_by_held);
  EXPECT_GE(10 * client.pointCount(), 9 * seen_by_held) << "only a few weak points may be gone";
  EXPECT_LT(client.pointCount(), edge.pointCount());
  EXPECT_EQ(size.points, client.pointCount());
  EXPECT_EQ(size.keyframes, held.size());
  EXPECT_GE(size.max_points, size.points);
}

}  // namespace
}  // namespace edgeslam
