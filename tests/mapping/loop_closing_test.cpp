// Loop closing on real frames: a there-and-back walk through 7-Scenes must be closed (monocular and
// RGB-D) and the closure must make the final trajectory more accurate; KITTI 07's first 160 frames
// (no revisit) must close no loop.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "eval/association.h"
#include "eval/ate.h"
#include "io/dataset.h"
#include "modes/edge_slam.h"
#include "modes/in_process_edge_link.h"
#include "modes/local_slam.h"
#include "place/vocabulary_training.h"
#include "support/shared_data.h"
#include "support/small_vocabulary.h"

namespace edgeslam {
namespace {

constexpr const char* kSevenScenes = "datasets/7scenes-redkitchen-1000";
constexpr const char* kKitti = "datasets/kitti07-160";

// A small vocabulary (k=10, L=4) from 50 images of both sequences, trained once per test process.
std::shared_ptr<const Vocabulary> testVocabulary() {
  static const std::shared_ptr<const Vocabulary> vocabulary = std::make_shared<const Vocabulary>(
      test::trainSmallVocabulary({{kSevenScenes, 25}, {kKitti, 16}}));
  return vocabulary;
}

struct Sequence {
  PinholeCamera camera;
  std::vector<DatasetFrame> frames;  // in playing order, timestamps made increasing
};

// Frames first, first + stride, ... up to last, then (when `and_back`) the same frames reversed;
// timestamps follow the playing order at the camera's rate divided by the stride.
Sequence makeSequence(std::size_t first, std::size_t last, std::size_t stride, bool and_back) {
  auto reader = openDataset(test::sharedPath(kSevenScenes));
  Sequence sequence;
  CameraIntrinsics intrinsics = reader->camera().intrinsics();
  const double fps = (intrinsics.fps > 0 ? intrinsics.fps : 30.0) / static_cast<double>(stride);
  intrinsics.fps = fps;
  sequence.camera = PinholeCamera(intrinsics);
  std::vector<DatasetFrame> forward;
  for (std::size_t i = first; i <= last; i += stride) forward.push_back(reader->load(i));
  const std::size_t n = forward.size();
  for (std::size_t k = 0; k < (and_back ? 2 * n : n); ++k) {
    DatasetFrame frame = forward[k < n ? k : 2 * n - 1 - k];
    frame.timestamp = static_cast<double>(k) / fps;
    sequence.frames.push_back(std::move(frame));
  }
  return sequence;
}

struct RunOutcome {
  std::size_t tracked = 0;
  std::size_t loops = 0;
  double ate_final_m = 0.0;
  std::size_t ate_pairs = 0;
  LoopCloserStats stats;
};

MappingBackendOptions backendOptions(bool loop_closing, std::size_t connected_older_than_frames,
                                     bool threaded) {
  MappingBackendOptions backend;
  backend.threaded = threaded;  // false: deterministic
  backend.vocabulary = testVocabulary();
  backend.loop_closing = loop_closing;
  backend.loop_closer.detector.connected_older_than_frames = connected_older_than_frames;
  // Revisit culling drops a new keyframe that an older one covers from the same viewpoint, with
  // shared points: exactly the connected revisits these tests turn into loops to exercise the
  // loop closer (the normal rule ignores connected keyframes, so it loses no real loop).
  backend.mapper.cull_revisits = connected_older_than_frames == 0;
  return backend;
}

RunOutcome run(const PinholeCamera& camera, const std::vector<DatasetFrame>& frames, Sensor sensor,
               bool loop_closing, std::size_t connected_older_than_frames = 0,
               bool threaded = false) {
  SlamOptions options = defaultSlamOptions(camera, sensor);
  options.backend = backendOptions(loop_closing, connected_older_than_frames, threaded);
  LocalSlam slam(camera, options);
  Trajectory ground_truth;
  RunOutcome out;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const DatasetFrame& frame = frames[k];
    ground_truth.push_back({frame.timestamp, *frame.ground_truth});
    const TrackResult r = slam.process(k, frame.timestamp, frame.gray, frame.depth);
    if (r.state == TrackingState::kOk) ++out.tracked;
  }
  slam.finish();
  out.loops = slam.counters().map.loops;
  if (slam.loopCloser() != nullptr) out.stats = slam.loopCloser()->stats();
  const AteResult ate =
      computeAte(associateByTimestamp(ground_truth, slam.trajectoryFinal()),
                 sensor == Sensor::kMonocular ? AlignMode::kSim3 : AlignMode::kSe3);
  out.ate_final_m = ate.translation.rmse;
  out.ate_pairs = ate.translation.count;
  return out;
}

void report(const char* name, const RunOutcome& with, const RunOutcome& without) {
  std::printf(
      "%s: loops %zu, ATE final %.4f m with loop closing, %.4f m without (%zu / %zu pairs)\n", name,
      with.loops, with.ate_final_m, without.ate_final_m, with.ate_pairs, without.ate_pairs);
  for (const LoopEvent& e : with.stats.events) {
    std::printf(
        "  loop frame %zu -> %zu: %d inliers, %d points, scale %.3f, moved %.3f m %.2f deg, "
        "%.1f ms (essential graph %.1f ms)\n",
        e.current_frame, e.loop_frame, e.sim3_inliers, e.matched_points, e.scale, e.translation_m,
        e.rotation_deg, e.correction_ms, e.pose_graph_ms);
  }
  for (const double ms : with.stats.global_ba_ms) std::printf("  global BA %.0f ms\n", ms);
}

// Tracking re-finds the outbound map all the way back (the return keyframes share points with up
// to ~23 outbound ones), so the walk is one connected map with ~2 cm final error and the normal
// rule, which ignores connected keyframes, finds no loop in it. To exercise detection,
// verification, correction and global BA on real frames, outbound keyframes at least 100 frames
// older are allowed as candidates here: the loop found must be right (many inliers, tiny
// correction) and must not make the trajectory worse.
// Searched for a sequence with drift to correct (this vocabulary, unthreaded): the whole walk at
// stride 2 (its end comes back to its start) stays one connected map, RGB-D 4.8 cm and mono 4.1 cm
// ATE, and the normal rule finds no loop (candidates fail verification with 7-19 BoW matches);
// with old connected keyframes allowed it closes 618 -> 214 and 894 -> 214 by moving the
// keyframe 1-6 mm. A there-and-back over 0..600 at stride 3 re-joins too (mono 3.3 cm), and a cut
// back to frame 0 after 0..500 is relocalised within 2 frames. This map has no drift to correct.
class ThereAndBack : public ::testing::TestWithParam<Sensor> {};

TEST_P(ThereAndBack, ClosesTheRevisitAndKeepsTheTrajectory) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const Sequence sequence = makeSequence(0, 100, 1, true);
  const Sensor sensor = GetParam();
  const RunOutcome with = run(sequence.camera, sequence.frames, sensor, true, 100);
  const RunOutcome without = run(sequence.camera, sequence.frames, sensor, false);
  report(toString(sensor), with, without);
  EXPECT_GE(with.tracked, sequence.frames.size() * 85 / 100);
  ASSERT_GE(with.loops, 1u);
  EXPECT_EQ(without.loops, 0u);
  for (const LoopEvent& e : with.stats.events) {
    // A revisit of the same frames: the current keyframe must come back near its outbound twin.
    EXPECT_GE(e.sim3_inliers, 40);
    // The two keyframes must show the same place (ground truth): close cameras, similar views.
    const SE3d& a = *sequence.frames[e.current_frame].ground_truth;
    const SE3d& b = *sequence.frames[e.loop_frame].ground_truth;
    EXPECT_LT((a.translation() - b.translation()).norm(), 0.6);
    EXPECT_GT(
        (a.rotation() * Eigen::Vector3d::UnitZ()).dot(b.rotation() * Eigen::Vector3d::UnitZ()),
        0.7);
    EXPECT_LT(e.translation_m, 0.05);
    EXPECT_LT(e.rotation_deg, 2.0);
    if (sensor != Sensor::kMonocular) {
      EXPECT_DOUBLE_EQ(e.scale, 1.0);
    }
  }
  EXPECT_GE(with.stats.global_ba_applied, 1u);
  EXPECT_LT(with.ate_final_m, without.ate_final_m + 0.003);
  EXPECT_LT(with.ate_final_m, 0.04);
}

// The same with mapping, loop closing and global BA on their own threads (as `run` does): the
// correction must not deadlock with mapping or tracking, and the final map must stay accurate.
TEST(LoopClosing, ThreadedThereAndBackCorrectsWithoutStalling) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const Sequence sequence = makeSequence(0, 100, 1, true);
  const RunOutcome r = run(sequence.camera, sequence.frames, Sensor::kRgbd, true, 100, true);
  report("rgbd threaded", r, r);
  EXPECT_GE(r.tracked, sequence.frames.size() * 85 / 100);
  EXPECT_EQ(r.stats.global_ba_applied + r.stats.global_ba_cancelled, r.stats.global_ba_started);
  EXPECT_LT(r.ate_final_m, 0.04);
}

// One back end for both modes: the options that make local mode close the there-and-back loop
// make an edge session close it too (the edge used to build its loop closer from the sensor's
// defaults, ignoring them, and found no loop here).
TEST(LoopClosing, EdgeSessionClosesTheLoopFromTheSameBackendOptions) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const Sequence sequence = makeSequence(0, 100, 1, true);
  const MappingBackendOptions backend = backendOptions(true, 100, false);
  EdgeMapSessionOptions edge_options;
  edge_options.backend = backend;
  auto link = std::make_unique<InProcessEdgeLink>(sequence.camera, Sensor::kRgbd, edge_options);
  InProcessEdgeLink* raw_link = link.get();
  EdgeSlam edge(sequence.camera, defaultSlamOptions(sequence.camera, Sensor::kRgbd),
                std::move(link));
  std::size_t tracked = 0;
  for (std::size_t k = 0; k < sequence.frames.size(); ++k) {
    const DatasetFrame& frame = sequence.frames[k];
    if (edge.process(k, frame.timestamp, frame.gray, frame.depth).state == TrackingState::kOk) {
      ++tracked;
    }
    raw_link->flush();
  }
  edge.finish();
  const LoopCloser* loop_closer = raw_link->session().loopCloser();
  ASSERT_NE(loop_closer, nullptr);
  std::printf("rgbd edge: %zu tracked, %zu loops on the edge, %llu reported to the client\n",
              tracked, loop_closer->loops(),
              static_cast<unsigned long long>(edge.counters().map.loops));
  EXPECT_GE(tracked, sequence.frames.size() * 85 / 100);
  EXPECT_GE(loop_closer->loops(), 1u);
  EXPECT_EQ(edge.counters().map.loops, loop_closer->loops());
  const RunOutcome local = run(sequence.camera, sequence.frames, Sensor::kRgbd, true, 100);
  EXPECT_GE(local.loops, 1u);
}

INSTANTIATE_TEST_SUITE_P(Sensors, ThereAndBack,
                         ::testing::Values(Sensor::kMonocular, Sensor::kRgbd),
                         [](const auto& sensor_info) {
                           return std::string(toString(sensor_info.param));
                         });

TEST(LoopClosing, NoFalseLoopOnKittiWithoutRevisit) {
  EDGESLAM_REQUIRE_SHARED(kKitti);
  auto reader = openDataset(test::sharedPath(kKitti));
  std::vector<DatasetFrame> frames;
  for (std::size_t i = 0; i < reader->info().frame_count; ++i) frames.push_back(reader->load(i));
  // Threaded (mapping and loop closing on their own threads, as in a real run): quicker here,
  // and the assertion does not depend on the exact interleaving.
  const RunOutcome r = run(reader->camera(), frames, Sensor::kMonocular, true, 0, true);
  std::printf("KITTI 07 0-159 mono: %zu tracked, %zu loops, %zu keyframes reached verification\n",
              r.tracked, r.loops, r.stats.keyframes_with_candidates);
  EXPECT_GE(r.stats.keyframes_processed, 10u);  // loop closing did look at the keyframes
  EXPECT_EQ(r.loops, 0u);
}

}  // namespace
}  // namespace edgeslam
