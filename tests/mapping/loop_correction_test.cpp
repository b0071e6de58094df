// A loop's correction solves the essential graph over the part of the map the loop is in: a part
// joined to it by no spanning-tree, loop or covisibility edge (another session's map not merged,
// the unconnected copies of a large stored map) is neither in the graph nor moved.
#include "mapping/loop_correction.h"

#include <gtest/gtest.h>

#include <vector>

#include "corridor_map.h"

namespace edgeslam {
namespace {

TEST(LoopCorrection, TheEssentialGraphHoldsThePartTheLoopIsInAndNoOther) {
  test::Corridor corridor{8};
  std::vector<KeyFrame*> other;  // sees points 1000.. only: joined to the corridor by nothing
  std::vector<SE3d> other_before;
  VerifiedLoop loop;
  {
    MutexLock lock(corridor.map.updateMutex());
    loop.current = corridor.keyframes.back();
    loop.loop = corridor.keyframes.front();
    for (int k = 0; k < 3; ++k) other.push_back(corridor.addKeyFrame(1000 + 10 * k));
    for (const KeyFrame* kf : other) other_before.push_back(kf->pose());
    corridor.map.takeChanges();
    // The corridor's last keyframe sees its first one's place again, 5 cm from where the map has
    // it.
    loop.S_cw = Sim3d(SE3d(loop.current->pose().rotation(),
                           loop.current->pose().translation() + Eigen::Vector3d(0.05, 0, 0)));
    // Its keypoints matched to the first keyframe's points: the link across the loop.
    loop.matched.assign(loop.current->features().keypoints.size(), nullptr);
    for (std::size_t i = 0; i < loop.matched.size(); ++i) {
      loop.matched[i] = corridor.point(static_cast<int>(i));
    }
  }
  const SE3d current_before = [&] {
    MutexLock lock(corridor.map.updateMutex());
    return loop.current->pose();
  }();
  const LoopCorrectionResult result =
      correctLoop(corridor.map, loop, corridor.camera, LoopCorrectionOptions{});
  ASSERT_TRUE(result.done);
  EXPECT_EQ(result.graph_vertices, 8u);
  MutexLock lock(corridor.map.updateMutex());
  EXPECT_GT((loop.current->pose().translation() - current_before.translation()).norm(), 0.01)
      << "the loop moved nothing";
  for (std::size_t k = 0; k < other.size(); ++k) {
    EXPECT_TRUE(other[k]->pose().matrix().isApprox(other_before[k].matrix(), 0.0))
        << "keyframe " << k << " of the other part moved";
  }
}

}  // namespace
}  // namespace edgeslam
