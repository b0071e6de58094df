// The global BA after a loop adjusts the part of the map the loop is in: a map of two parts that
// share no point (two sessions not merged, the unconnected copies of a large stored map) leaves
// the other part as it is, and a part above the bound is not adjusted at all.
#include "mapping/loop_global_ba.h"

#include <gtest/gtest.h>

#include <atomic>
#include <vector>

#include "corridor_map.h"

namespace edgeslam {
namespace {

struct TwoCorridors {
  test::Corridor corridor{8};
  std::vector<KeyFrame*> second;  // sees points 1000.. only: joined to the first by nothing

  TwoCorridors() {
    MutexLock lock(corridor.map.updateMutex());
    for (int k = 0; k < 3; ++k) second.push_back(corridor.addKeyFrame(1000 + 10 * k));
    corridor.map.takeChanges();
  }
};

TEST(LoopGlobalBundleAdjustment, FindsTheKeyFramesJoinedByPointsAndNoOthers) {
  TwoCorridors m;
  MutexLock lock(m.corridor.map.updateMutex());
  EXPECT_EQ(connectedKeyFrames(m.corridor.map, m.corridor.keyframes.front()).size(), 8u);
  EXPECT_EQ(connectedKeyFrames(m.corridor.map, m.second.back()).size(), 3u);
  EXPECT_TRUE(connectedKeyFrames(m.corridor.map, nullptr).empty());
}

TEST(LoopGlobalBundleAdjustment, AdjustsTheLoopsPartAndLeavesTheOtherAsItIs) {
  TwoCorridors m;
  std::vector<SE3d> first_before;
  {
    MutexLock lock(m.corridor.map.updateMutex());
    for (int k = 0; k < 8; ++k) first_before.push_back(m.corridor.keyframes[k]->pose());
  }
  const LoopGlobalBundleAdjustmentResult result = runLoopGlobalBundleAdjustment(
      m.corridor.map, m.corridor.camera, nullptr, 3, {}, m.second.front(), 0);
  EXPECT_EQ(result.keyframes, 3u);
  EXPECT_EQ(result.points, 60u);  // points 1000-1059
  EXPECT_TRUE(result.applied);
  MutexLock lock(m.corridor.map.updateMutex());
  for (int k = 0; k < 8; ++k) {
    EXPECT_TRUE(m.corridor.keyframes[k]->pose().matrix().isApprox(first_before[k].matrix(), 0.0))
        << "keyframe " << k << " of the other part moved";
  }
}

TEST(LoopGlobalBundleAdjustment, APartAboveTheBoundIsNotAdjusted) {
  TwoCorridors m;
  const LoopGlobalBundleAdjustmentResult too_large = runLoopGlobalBundleAdjustment(
      m.corridor.map, m.corridor.camera, nullptr, 3, {}, m.corridor.keyframes.front(), 7);
  EXPECT_TRUE(too_large.too_large);
  EXPECT_FALSE(too_large.applied);
  EXPECT_EQ(too_large.keyframes, 8u);
  // The small part fits under the same bound.
  const LoopGlobalBundleAdjustmentResult small = runLoopGlobalBundleAdjustment(
      m.corridor.map, m.corridor.camera, nullptr, 3, {}, m.second.front(), 7);
  EXPECT_FALSE(small.too_large);
  EXPECT_EQ(small.keyframes, 3u);
}

// A loop correction cancels a global BA without waiting for its solve; when the cancellation comes
// after the solve, while the run waits for the map (the correction holds it), nothing is written.
TEST(LoopGlobalBundleAdjustment, ARunCancelledBeforeItsWriteBackChangesNothing) {
  for (const bool cancelled_meanwhile : {false, true}) {
    TwoCorridors m;
    std::vector<Eigen::Vector3d> before;
    {
      MutexLock lock(m.corridor.map.updateMutex());
      for (int i = 1000; i < 1060; ++i) before.push_back(m.corridor.point(i)->position());
    }
    std::atomic<bool> cancel{false};
    GlobalBundleAdjustmentHooks hooks;
    hooks.before_apply = [&] { cancel = cancelled_meanwhile; };
    const LoopGlobalBundleAdjustmentResult result = runLoopGlobalBundleAdjustment(
        m.corridor.map, m.corridor.camera, &cancel, 5, hooks, m.second.front(), 0);
    EXPECT_EQ(result.cancelled, cancelled_meanwhile);
    EXPECT_EQ(result.applied, !cancelled_meanwhile);
    MutexLock lock(m.corridor.map.updateMutex());
    std::size_t moved = 0;
    for (int i = 1000; i < 1060; ++i) {
      const MapPoint* p = m.corridor.point(i);
      if (p == nullptr || !p->position().isApprox(before[static_cast<std::size_t>(i - 1000)], 0.0))
        ++moved;
    }
    if (cancelled_meanwhile) {
      EXPECT_EQ(moved, 0u) << "a cancelled run wrote its solution";
    } else {
      EXPECT_GT(moved, 0u) << "the run that was not cancelled moved nothing";
    }
  }
}

}  // namespace
}  // namespace edgeslam
