// Edge mode, monocular, with the client triangulating its own points at each keyframe: on KITTI 07
// the client makes points (through bag of words), the edge keeps them, and the client's map stays a
// faithful replica of the edge's; behind an edge that answers several keyframes late, the client
// keeps tracking.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <vector>

#include "eval/association.h"
#include "eval/ate.h"
#include "io/dataset.h"
#include "modes/edge_slam.h"
#include "place/vocabulary_training.h"
#include "server/edge_map_session.h"
#include "support/shared_data.h"
#include "support/small_vocabulary.h"

namespace edgeslam {
namespace {

constexpr const char* kKitti = "datasets/kitti07-160";

// A small vocabulary (k=10, L=4) from every 10th frame of the sequence, trained once per process.
std::shared_ptr<const Vocabulary> kittiVocabulary() {
  static const std::shared_ptr<const Vocabulary> vocabulary =
      std::make_shared<const Vocabulary>(test::trainSmallVocabulary({{kKitti, 10}}, 2000));
  return vocabulary;
}

// An edge that answers late: uploads wait in the link until deliver(), which maps them in order
// and hands their slices to the client at once.
class LaggingEdgeLink : public EdgeLink {
 public:
  LaggingEdgeLink(const PinholeCamera& camera, EdgeMapSessionOptions options)
      : session_(camera, Sensor::kMonocular, std::move(options), [this](MapSlice slice) {
          if (handler_) handler_(std::move(slice));
        }) {}

  void send(KeyFrameUpload upload) override { queue_.push_back(std::move(upload)); }
  std::uint8_t idOrigin() const override { return 1; }
  void setSliceHandler(SliceHandler handler) override { handler_ = std::move(handler); }
  EdgeLinkCounters counters() const override { return {}; }
  void close() override {}

  void deliver() {
    std::vector<KeyFrameUpload> uploads;
    uploads.swap(queue_);
    for (const KeyFrameUpload& upload : uploads) session_.onKeyFrame(upload);
  }
  EdgeMapSession& session() { return session_; }

 private:
  EdgeMapSession session_;
  SliceHandler handler_;
  std::vector<KeyFrameUpload> queue_;
};

struct EdgeRun {
  std::unique_ptr<EdgeSlam> slam;
  LaggingEdgeLink* link = nullptr;
  std::size_t tracked = 0;
  std::size_t first_tracked = 0;
  double ate_rmse = 0.0;
};

// `frames` of KITTI; the edge maps the uploads every `lag` frames (1: before the next frame).
EdgeRun runKitti(std::size_t frames, std::size_t lag, bool client_triangulation) {
  auto reader = openDataset(test::sharedPath(kKitti));
  const PinholeCamera& camera = reader->camera();
  SlamOptions options = defaultSlamOptions(camera, Sensor::kMonocular);
  options.tracker.vocabulary = kittiVocabulary();
  options.client_triangulation = client_triangulation;
  EdgeMapSessionOptions edge_options;
  edge_options.backend.threaded = false;
  edge_options.backend.vocabulary = kittiVocabulary();
  edge_options.backend.loop_closing = false;
  auto link = std::make_unique<LaggingEdgeLink>(camera, edge_options);
  EdgeRun run;
  run.link = link.get();
  run.slam = std::make_unique<EdgeSlam>(camera, options, std::move(link));
  run.slam->finish_timeout_s = 1.0;
  Trajectory ground_truth;
  run.first_tracked = frames;
  for (std::size_t i = 0; i < frames; ++i) {
    const DatasetFrame frame = reader->load(i);
    ground_truth.push_back({frame.timestamp, *frame.ground_truth});
    if (run.slam->process(i, frame.timestamp, frame.gray, frame.depth).state ==
        TrackingState::kOk) {
      ++run.tracked;
      run.first_tracked = std::min(run.first_tracked, i);
    }
    if ((i + 1) % lag == 0) run.link->deliver();
  }
  run.link->deliver();
  run.slam->finish();
  run.ate_rmse =
      computeAte(associateByTimestamp(ground_truth, run.slam->trajectoryFinal()), AlignMode::kSim3)
          .translation.rmse;
  return run;
}

// Client and edge hold the same keyframes and points, each point where the edge has it and seen
// as often.
void expectClientReplicatesEdge(EdgeRun& run) {
  Map& edge = run.link->session().map();
  const Map& client = run.slam->map();
  MutexLock edge_lock(edge.updateMutex());
  MutexLock client_lock(client.updateMutex());
  EXPECT_EQ(client.keyFrameCount(), edge.keyFrameCount());
  EXPECT_EQ(client.pointCount(), edge.pointCount());
  for (MapPoint* p : edge.mapPoints()) {
    const MapPoint* replica = client.mapPoint(p->id());
    ASSERT_NE(replica, nullptr) << "edge point " << p->id() << " missing on the client";
    EXPECT_LT((replica->position() - p->position()).norm(), 1e-9);
    EXPECT_EQ(replica->observations().size(), p->observations().size()) << "point " << p->id();
  }
}

// Points in the edge's map that the client triangulated: made by the client (its id origin) in a
// keyframe after the two the monocular initialisation made, seen twice or more.
std::size_t clientTriangulatedPointsOnTheEdge(EdgeRun& run) {
  Map& edge = run.link->session().map();
  MutexLock lock(edge.updateMutex());
  const std::vector<KeyFrame*> keyframes = edge.keyFrames();
  if (keyframes.size() < 2) return 0;
  const KeyFrameId second = keyframes[1]->id();
  std::size_t count = 0;
  for (MapPoint* p : edge.mapPoints()) {
    if (idOrigin(p->id()) == 1 && p->firstKeyFrameId() > second && p->observationCount() >= 2) {
      ++count;
    }
  }
  return count;
}

TEST(ClientTriangulation, EdgeKeepsTheClientsPointsAndTheMapsStayReplicasOnKitti) {
  EDGESLAM_REQUIRE_SHARED(kKitti);
  EdgeRun with = runKitti(50, 1, true);
  EdgeRun without = runKitti(50, 1, false);
  const KeyFrameTriangulationStats& stats = with.slam->tracker().triangulationStats();
  const std::size_t on_edge = clientTriangulatedPointsOnTheEdge(with);
  std::printf(
      "client triangulation: %zu keyframes, %zu searches (%zu bow), %zu points (%zu on the edge), "
      "%.2f ms median per keyframe; tracked %zu vs %zu without, ATE %.3f vs %.3f m\n",
      stats.keyframes, stats.searches, stats.bow_searches, stats.points_created, on_edge,
      stats.ms.summary().median, with.tracked, without.tracked, with.ate_rmse, without.ate_rmse);
  EXPECT_GT(stats.keyframes, 10u);
  EXPECT_EQ(stats.bow_searches, stats.searches);
  EXPECT_GT(stats.points_created, 20 * stats.keyframes);
  EXPECT_GT(on_edge, 200u);
  EXPECT_EQ(without.slam->tracker().triangulationStats().keyframes, 0u);
  EXPECT_EQ(clientTriangulatedPointsOnTheEdge(without), 0u);
  // Tracks as well as with the edge's points alone.
  EXPECT_GE(with.tracked, without.tracked);
  EXPECT_LT(with.ate_rmse, std::max(1.5 * without.ate_rmse, without.ate_rmse + 0.1));
  expectClientReplicatesEdge(with);
}

// The edge maps the client's keyframes only every 8 frames (0.8 s of KITTI): without its own
// points the client runs out of points to track; with them it tracks on, and the maps, where
// edge and client made points on the same keypoints meanwhile, are replicas again at the end.
TEST(ClientTriangulation, ClientKeepsTrackingBehindALaggingEdgeOnKitti) {
  EDGESLAM_REQUIRE_SHARED(kKitti);
  constexpr std::size_t kFrames = 60;
  EdgeRun with = runKitti(kFrames, 8, true);
  EdgeRun without = runKitti(kFrames, 8, false);
  std::printf(
      "edge 8 frames late: tracked %zu (from frame %zu) vs %zu without; ATE %.3f vs %.3f m\n",
      with.tracked, with.first_tracked, without.tracked, with.ate_rmse, without.ate_rmse);
  EXPECT_LT(with.first_tracked, 10u);
  EXPECT_GE(with.tracked, kFrames - with.first_tracked - 2);
  EXPECT_GT(with.tracked, without.tracked);
  EXPECT_LT(with.ate_rmse, 0.6);
  expectClientReplicatesEdge(with);
}

}  // namespace
}  // namespace edgeslam
