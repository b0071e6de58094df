// Edge mode with the edge in the same process: the client's map must stay a faithful replica of
// the edge's global map, and tracking as good as in local mode.
#include "pipeline/edge_slam.h"

#include <gtest/gtest.h>

#include "eval/ate.h"
#include "io/dataset.h"
#include "pipeline/in_process_edge_link.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

TEST(EdgeSlam, ClientMapReplicatesTheEdgeMapOnKitti) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  auto reader = openDataset(test::sharedPath("datasets/kitti07-160"));
  const PinholeCamera& camera = reader->camera();
  SlamOptions options = defaultSlamOptions(camera, Sensor::kMonocular);
  EdgeMapSessionOptions edge_options;
  edge_options.threaded = false;
  auto link = std::make_unique<InProcessEdgeLink>(camera, Sensor::kMonocular, edge_options);
  InProcessEdgeLink* raw_link = link.get();
  EdgeSlam slam(camera, options, std::move(link));
  for (std::size_t i = 0; i < 30; ++i) {
    const DatasetFrame frame = reader->load(i);
    slam.process(i, frame.timestamp, frame.gray, frame.depth);
    raw_link->flush();
  }
  slam.finish();
  Map& edge = raw_link->session().map();
  std::lock_guard edge_lock(edge.updateMutex());
  EXPECT_GT(edge.pointCount(), 300u);
  EXPECT_EQ(slam.keyFrameCount(), edge.keyFrameCount());
  EXPECT_EQ(slam.mapPointCount(), edge.pointCount());
  for (MapPoint* p : edge.mapPoints()) {
    const MapPoint* replica = slam.map().mapPoint(p->id());
    ASSERT_NE(replica, nullptr) << "edge point " << p->id() << " missing on the client";
    EXPECT_LT((replica->position() - p->position()).norm(), 1e-9);
    EXPECT_EQ(replica->observations().size(), p->observations().size());
  }
  const Trajectory client_keyframes = slam.keyframeTrajectory();
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

}  // namespace
}  // namespace edgeslam
